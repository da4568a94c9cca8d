#include "brdf/device/simulator.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <thread>
#include <tuple>

#include "brdf/core/error.h"
#include "brdf/core/text_format.h"
#include "brdf/core/virtual_capture.h"
#include "brdf/device/white_reference.h"

namespace brdf::device {
namespace {

InstrumentModel MakeReferenceModel() {
  InstrumentModel m;
  m.model = "BRDF-SIM MD2";
  m.firmware_version = "2.4.1-sim";
  // The reference geometry is defined once, in brdf::core (virtual_capture.h).
  m.SetGeometry(ReferenceGeometry());
  // A 16-bit camera-type detector: ~32,800 e⁻ full well at 2 counts per electron, 6 counts of
  // read noise, a bias near 500 counts. Responsivities give the Spectralon panel at normal
  // incidence (L = 0.315) about 600 counts/ms, so it auto-ranges to ~80 ms; the darkest
  // library samples at θin = 60° still reach > 10,000 counts within the 2 s maximum, while
  // the sharpest specular peaks (diamond) clip even at the 1 ms minimum.
  m.adc_full_scale_counts = 65535;
  m.frames_per_reading = 16;
  m.dark_frames = 64;
  m.white_frames = 64;
  m.dark_offset_counts = {496, 512, 504};
  m.read_noise_counts = 6;
  m.conversion_gain_counts_per_electron = 2;
  m.responsivity_counts_per_ms = {1800, 2000, 1400};
  m.min_exposure_ms = 1;
  m.max_exposure_ms = 2000;
  m.autorange_target_fraction = 0.8;
  return m;
}

}  // namespace

void InstrumentModel::SetGeometry(const CaptureGeometry& g) {
  theta_in_deg.assign(g.theta_in_deg.begin(), g.theta_in_deg.end());
  theta_out_max_deg = static_cast<float>(g.theta_out_max_deg);
  theta_out_step_deg = static_cast<float>(g.theta_out_step_deg);
  phi_out_step_deg = static_cast<float>(g.phi_out_step_deg);
}

namespace {

const std::vector<InstrumentModel>& ModelTable() {
  static const std::vector<InstrumentModel> kTable = {MakeReferenceModel()};
  return kTable;
}

// SplitMix64 finaliser: decorrelates seeds that differ in a few bits.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

enum : std::uint64_t { kSeedDark = 1, kSeedWhite = 2, kSeedSlice = 3 };

constexpr std::uint16_t kWhiteRow = 0xFFFF;

double MaxOf(const std::array<double, 3>& v) { return std::max({v[0], v[1], v[2]}); }

// Lambertian panel with the certificate reflectance (the default white reference).
class LambertianPanel final : public BrdfSource {
 public:
  explicit LambertianPanel(const std::array<double, 3>& rho) : rho_(rho) {}
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    if (!(wi.z > 0) || !(wo.z > 0)) return {0, 0, 0};
    return {rho_[0] * kInvPi, rho_[1] * kInvPi, rho_[2] * kInvPi};
  }
  std::string Name() const override { return "Spectralon white reference"; }

 private:
  std::array<double, 3> rho_;
};

}  // namespace

bool FaultPlan::Has(FaultType type, std::uint64_t at) const {
  return std::any_of(faults.begin(), faults.end(),
                     [&](const Fault& f) { return f.type == type && f.at == at; });
}

bool FaultPlan::HasFirmwareFaults() const {
  return std::any_of(faults.begin(), faults.end(),
                     [](const Fault& f) { return f.type != FaultType::kEndpointHalt; });
}

FaultPlan ParseFaultPlan(std::string_view spec) {
  static constexpr std::pair<std::string_view, FaultType> kNames[] = {
      {"disconnect", FaultType::kDisconnect},
      {"stall", FaultType::kStall},
      {"timeout", FaultType::kTimeout},
      {"corrupt", FaultType::kCorrupt},
      {"duplicate", FaultType::kDuplicate},
      {"reorder", FaultType::kReorder},
      {"lamp", FaultType::kLampFailure},
      {"contact", FaultType::kSampleContact},
      {"overtemp", FaultType::kOverTemperature},
      {"halt", FaultType::kEndpointHalt},
      {"hold", FaultType::kHold}};
  std::string names;
  for (const auto& [name, type] : kNames) names += (names.empty() ? "" : ", ") + std::string(name);
  FaultPlan plan;
  std::size_t start = 0;
  while (start <= spec.size() && !spec.empty()) {
    std::size_t end = spec.find(',', start);
    if (end == std::string_view::npos) end = spec.size();
    const std::string item(spec.substr(start, end - start));
    const std::size_t colon = item.find(':');
    const std::string kind = item.substr(0, colon);
    const std::string value = colon == std::string::npos ? "" : item.substr(colon + 1);
    const auto it = std::find_if(std::begin(kNames), std::end(kNames),
                                 [&](const auto& k) { return k.first == kind; });
    if (it == std::end(kNames))
      throw InvalidArgument("simulated fault '" + item + "': expected NAME:N with NAME one of " +
                            names);
    std::uint64_t n = 0;
    bool digits = !value.empty() && value.size() <= 18;
    for (char c : value) {
      digits = digits && c >= '0' && c <= '9';
      if (digits) n = n * 10 + static_cast<std::uint64_t>(c - '0');
    }
    if (!digits || n == 0)
      throw InvalidArgument("simulated fault '" + item +
                            "': expected a frame number ≥ 1 after the colon, got '" + value + "'");
    plan.faults.push_back({it->second, n});
    start = end + 1;
    if (end == spec.size()) break;
  }
  return plan;
}

std::span<const InstrumentModel> InstrumentModels() { return ModelTable(); }

const InstrumentModel& ReferenceInstrument() { return ModelTable().front(); }

const InstrumentModel& FindInstrumentModel(std::string_view model) {
  std::string names;
  for (const InstrumentModel& m : ModelTable()) {
    if (m.model == model) return m;
    names += (names.empty() ? "" : ", ") + m.model;
  }
  throw InvalidArgument("unknown instrument model '" + std::string(model) + "' (known: " + names +
                        ")");
}

SimulatedFirmware::SimulatedFirmware(SimulatorConfig config) : config_(std::move(config)) {
  const InstrumentModel& m = config_.model;
  if (!config_.sample) throw InvalidArgument("simulator: no virtual sample given");
  if (!(config_.noise_level >= 0) || !std::isfinite(config_.noise_level))
    throw InvalidArgument("simulator: noise level must be a finite number ≥ 0, got " +
                          std::to_string(config_.noise_level));
  if (m.theta_in_deg.empty() || m.theta_in_deg.size() > 255)
    throw InvalidArgument("simulator: between 1 and 255 incidence angles needed, got " +
                          std::to_string(m.theta_in_deg.size()));
  for (float t : m.theta_in_deg)
    if (!(t >= 0 && t < 90))
      throw InvalidArgument("simulator: incidence angle must be in [0, 90) degrees, got " +
                            std::to_string(t));
  if (!(m.theta_out_max_deg >= 0 && m.theta_out_max_deg < 90))
    throw InvalidArgument("simulator: largest θout must be in [0, 90) degrees, got " +
                          std::to_string(m.theta_out_max_deg));
  if (!(m.theta_out_step_deg >= 0.01f && m.phi_out_step_deg >= 0.01f && m.phi_out_step_deg <= 360))
    throw InvalidArgument("simulator: angular steps must be in [0.01, 360] degrees, got θout " +
                          std::to_string(m.theta_out_step_deg) + ", φout " +
                          std::to_string(m.phi_out_step_deg));
  if (m.frames_per_reading < 1 || m.dark_frames < 2 || m.white_frames < 1 ||
      !(m.min_exposure_ms > 0) || !(m.max_exposure_ms >= m.min_exposure_ms) ||
      m.nd_transmittance.empty() || m.nd_transmittance.size() > 255 ||
      m.nd_transmittance[0] != 1.0f ||
      !std::all_of(m.nd_transmittance.begin(), m.nd_transmittance.end(),
                   [](float t) { return t > 0 && t <= 1; }))
    throw InvalidArgument("simulator: instrument model '" + m.model + "' has unusable constants");

  geometry_.theta_in_deg = m.theta_in_deg;
  geometry_.theta_out_max_deg = m.theta_out_max_deg;
  geometry_.theta_out_step_deg = m.theta_out_step_deg;
  geometry_.phi_out_step_deg = m.phi_out_step_deg;
  const double rows = std::floor(static_cast<double>(m.theta_out_max_deg) /
                                     static_cast<double>(m.theta_out_step_deg) +
                                 1e-6) +
                      1;
  const double columns = std::ceil(360.0 / static_cast<double>(m.phi_out_step_deg) - 1e-6);
  if (rows > 65535 || columns > 65535)
    throw InvalidArgument("simulator: geometry of " + std::to_string(rows) + " × " +
                          std::to_string(columns) + " samples exceeds 65535 per axis");
  geometry_.rows = static_cast<std::uint16_t>(rows);
  geometry_.min_exposure_ms = static_cast<float>(m.min_exposure_ms);
  geometry_.max_exposure_ms = static_cast<float>(m.max_exposure_ms);
  geometry_.nd_transmittance = m.nd_transmittance;
  geometry_.columns = static_cast<std::uint16_t>(columns);
  column_cos_phi_.resize(geometry_.columns);
  column_sin_phi_.resize(geometry_.columns);
  for (std::size_t col = 0; col < geometry_.columns; ++col) {
    const double phi = DegToRad(geometry_.PhiOutDeg(col));
    column_cos_phi_[col] = std::cos(phi);
    column_sin_phi_[col] = std::sin(phi);
  }

  white_ = config_.white_reference;
  if (!white_) white_ = std::make_shared<LambertianPanel>(SpectralonWhiteReference().rho);
}

void SimulatedFirmware::Receive(std::span<const std::uint8_t> bytes) {
  if (!link_up_) throw DeviceError("simulated instrument " + config_.serial + ": link is down");
  if (stalled_) return;
  input_.Append(bytes);
  for (;;) {
    DecodeResult r = input_.Next();
    if (r.status == DecodeStatus::kNeedMore) break;
    if (r.status == DecodeStatus::kInvalid) {
      if (r.corrupt) SendError(ErrorCode::kBadFrame, 0, "damaged frame received: " + r.reason);
      continue;
    }
    Handle(r.frame);
  }
}

std::size_t SimulatedFirmware::Transmit(std::span<std::uint8_t> out) {
  if (output_start_ == output_.size()) {
    output_.clear();
    output_start_ = 0;
    while (output_.empty() && streaming_ && link_up_ && !stalled_) ProduceStreamFrame();
  }
  const std::size_t n = std::min(out.size(), output_.size() - output_start_);
  std::copy_n(output_.begin() + static_cast<std::ptrdiff_t>(output_start_), n, out.begin());
  output_start_ += n;
  return n;
}

void SimulatedFirmware::Send(MessageType type, const std::vector<std::uint8_t>& payload) {
  if (!link_up_ || stalled_ || hung_) return;
  ++frames_sent_;
  const std::uint64_t n = frames_sent_;
  if (type == MessageType::kSliceBegin)
    stream_frame_ = 1;
  else if (type == MessageType::kRowData || type == MessageType::kSliceEnd)
    ++stream_frame_;
  else
    stream_frame_ = 0;
  // The faults that apply to this frame, by type: frame-numbered ones at frame n, slice-relative
  // ones at their frame of the first stream at their θin.
  const std::vector<Fault>& faults = config_.faults.faults;
  slice_fault_fired_.resize(faults.size(), false);
  std::uint32_t firing = 0;
  for (std::size_t i = 0; i < faults.size(); ++i) {
    const Fault& fault = faults[i];
    bool hit = false;
    if (!fault.in_slice_theta_in_deg) {
      hit = fault.at == n;
    } else if (!slice_fault_fired_[i] && stream_frame_ == fault.at &&
               std::fabs(*fault.in_slice_theta_in_deg - slice_theta_in_deg_) <= 1e-4f) {
      hit = true;
      // Damage to one transfer happens once; a failed lamp, a lost contact or an overheated
      // detector stays so, for every stream at that θin (a host that missed the error report
      // meets it again).
      slice_fault_fired_[i] = fault.type != FaultType::kLampFailure &&
                              fault.type != FaultType::kSampleContact &&
                              fault.type != FaultType::kOverTemperature;
    }
    if (hit) firing |= 1u << static_cast<unsigned>(fault.type);
  }
  struct {
    std::uint32_t bits;
    bool Has(FaultType t, std::uint64_t) const { return (bits >> static_cast<unsigned>(t)) & 1u; }
  } const f{firing};
  if (f.Has(FaultType::kDisconnect, n)) {
    link_up_ = false;
    streaming_ = false;
    return;
  }
  if (f.Has(FaultType::kStall, n)) {
    stalled_ = true;
    streaming_ = false;
    return;
  }
  if (f.Has(FaultType::kTimeout, n) || f.Has(FaultType::kHold, n)) {
    hung_ = true;
    streaming_ = false;
    if (f.Has(FaultType::kHold, n)) {
      held_ = true;
      if (config_.on_hold) config_.on_hold(n);
    }
    return;
  }
  for (const auto& [fault, code, text] :
       {std::tuple{FaultType::kLampFailure, ErrorCode::kLampFailure,
                   "lamp failure: the light source did not reach its set point"},
        std::tuple{FaultType::kSampleContact, ErrorCode::kSampleNotInContact,
                   "sample not in contact with the measurement port"},
        std::tuple{FaultType::kOverTemperature, ErrorCode::kOverTemperature,
                   "detector over temperature"}}) {
    if (f.Has(fault, n)) {
      streaming_ = false;
      std::vector<std::uint8_t> bytes;
      AppendFrame(bytes, static_cast<std::uint8_t>(MessageType::kError), sequence_++,
                  EncodeError({code,
                               type == MessageType::kRowData || type == MessageType::kSliceEnd
                                   ? static_cast<std::uint8_t>(MessageType::kMeasureSlice)
                                   : static_cast<std::uint8_t>(0),
                               text}));
      output_.insert(output_.end(), bytes.begin(), bytes.end());
      return;
    }
  }
  std::vector<std::uint8_t> bytes;
  AppendFrame(bytes, static_cast<std::uint8_t>(type), sequence_++, payload);
  if (f.Has(FaultType::kCorrupt, n)) {
    // One flipped bit in the payload (or in the CRC of an empty frame): line noise.
    const std::size_t at =
        payload.empty() ? bytes.size() - 1 : kFrameHeaderBytes + payload.size() / 2;
    bytes[at] ^= 0x10;
  }
  if (f.Has(FaultType::kReorder, n)) {
    held_frame_ = std::move(bytes);
    return;
  }
  output_.insert(output_.end(), bytes.begin(), bytes.end());
  if (f.Has(FaultType::kDuplicate, n)) output_.insert(output_.end(), bytes.begin(), bytes.end());
  if (!held_frame_.empty() && !f.Has(FaultType::kReorder, n)) {
    output_.insert(output_.end(), held_frame_.begin(), held_frame_.end());
    held_frame_.clear();
  }
}

void SimulatedFirmware::SendError(ErrorCode code, std::uint8_t request_type,
                                  const std::string& message) {
  Send(MessageType::kError, EncodeError({code, request_type, message}));
}

bool SimulatedFirmware::FindThetaIn(float theta_in_deg) const {
  return std::any_of(geometry_.theta_in_deg.begin(), geometry_.theta_in_deg.end(),
                     [&](float t) { return std::fabs(t - theta_in_deg) <= 1e-4f; });
}

void SimulatedFirmware::Handle(const Frame& frame) {
  const auto type = static_cast<MessageType>(frame.type);
  if (hung_) {
    if (type != MessageType::kAbort) return;
    hung_ = false;  // the host's ABORT wakes a hung firmware
    if (held_) {
      held_ = false;
      if (config_.on_hold_released) config_.on_hold_released();
    }
  }
  if (streaming_) {
    if (type == MessageType::kAbort) {
      streaming_ = false;
      Send(MessageType::kAck, EncodeAck(frame.type));
    } else {
      SendError(ErrorCode::kBusy, frame.type,
                "a slice is streaming; only ABORT is accepted until SLICE_END");
    }
    return;
  }
  const InstrumentModel& m = config_.model;
  try {
    switch (type) {
      case MessageType::kIdentify: {
        IdentityInfo info;
        info.model = m.model;
        info.serial = config_.serial;
        info.firmware_version = m.firmware_version;
        info.adc_full_scale_counts = static_cast<float>(m.adc_full_scale_counts);
        info.frames_per_reading = static_cast<std::uint16_t>(m.frames_per_reading);
        info.shot_variance_per_count = static_cast<float>(
            config_.noise_level * config_.noise_level * m.conversion_gain_counts_per_electron);
        Send(MessageType::kIdentity, EncodeIdentity(info));
        return;
      }
      case MessageType::kGetGeometry:
        Send(MessageType::kGeometry, EncodeGeometry(geometry_));
        return;
      case MessageType::kSetExposure: {
        const ExposureSetting s = DecodeExposure(frame.payload);
        if (s.mode == ExposureMode::kFixed &&
            !(s.exposure_ms >= m.min_exposure_ms && s.exposure_ms <= m.max_exposure_ms)) {
          SendError(ErrorCode::kBadArgument, frame.type,
                    "exposure " + ShortNumberText(s.exposure_ms) + " ms outside [" +
                        ShortNumberText(m.min_exposure_ms) + ", " +
                        ShortNumberText(m.max_exposure_ms) + "] ms");
          return;
        }
        exposure_ = s;
        Send(MessageType::kAck, EncodeAck(frame.type));
        return;
      }
      case MessageType::kMeasureDark: {
        Reseed(kSeedDark, 0);
        const double s = config_.noise_level;
        DarkReading d;
        d.frames = static_cast<std::uint16_t>(m.dark_frames);
        for (int c = 0; c < 3; ++c) {
          double sum = 0, sum2 = 0;
          for (int i = 0; i < m.dark_frames; ++i) {
            double x = s * m.dark_offset_counts[c];
            if (s > 0)
              x = std::clamp(x + s * m.read_noise_counts * normal_(rng_), 0.0,
                             m.adc_full_scale_counts);
            sum += x;
            sum2 += x * x;
          }
          const double n = m.dark_frames;
          const double mean = sum / n;
          d.mean_counts[c] = static_cast<float>(mean);
          d.read_noise_counts[c] =
              static_cast<float>(std::sqrt(std::max(0.0, (sum2 - n * mean * mean) / (n - 1))));
        }
        Send(MessageType::kDark, EncodeDark(d));
        return;
      }
      case MessageType::kMeasureWhite: {
        const float theta_in = DecodeThetaIn(frame.payload);
        if (!FindThetaIn(theta_in)) {
          SendError(ErrorCode::kBadArgument, frame.type,
                    "θin " + std::to_string(theta_in) + "° is not a position of the light arm");
          return;
        }
        // The panel is read in the surface normal direction; it is Lambertian, so any
        // direction gives the same radiance.
        const Vec3 light = SphericalDirectionDeg(theta_in, 0);
        const Rgb f = white_->Eval(light, Vec3{0, 0, 1});
        std::array<double, 3> rate{};
        for (int c = 0; c < 3; ++c) rate[c] = m.responsivity_counts_per_ms[c] * f[c] * light.z;
        const Exposure t = AutoExposure(MaxOf(rate));
        Reseed(kSeedWhite, theta_in);
        const Reading r = Read(rate, t, m.white_frames);
        if (r.clipped != 0) clip_log_.push_back({theta_in, kWhiteRow, kWhiteRow, r.clipped});
        WhiteReading w;
        w.theta_in_deg = theta_in;
        w.exposure_ms = t.ms;
        w.nd_index = t.nd;
        w.counts = r.counts;
        w.clipped_channels = r.clipped;
        w.frames = static_cast<std::uint16_t>(m.white_frames);
        Send(MessageType::kWhite, EncodeWhite(w));
        return;
      }
      case MessageType::kMeasureSlice: {
        const float theta_in = DecodeThetaIn(frame.payload);
        if (!FindThetaIn(theta_in)) {
          SendError(ErrorCode::kBadArgument, frame.type,
                    "θin " + std::to_string(theta_in) + "° is not a position of the light arm");
          return;
        }
        StartSlice(theta_in);
        return;
      }
      case MessageType::kAbort:
        Send(MessageType::kAck, EncodeAck(frame.type));  // nothing to abort
        return;
      default:
        SendError(ErrorCode::kUnknownCommand, frame.type,
                  "unknown command " + MessageTypeName(frame.type));
        return;
    }
  } catch (const DeviceError& e) {
    SendError(ErrorCode::kBadPayload, frame.type, e.what());
  }
}

void SimulatedFirmware::Reseed(std::uint64_t what, float theta_in_deg) {
  const std::uint64_t key =
      Mix(config_.seed) ^ Mix(what * 0x100000000ull + std::bit_cast<std::uint32_t>(theta_in_deg));
  rng_.seed(Mix(key));
  normal_.reset();
}

void SimulatedFirmware::StartSlice(float theta_in_deg) {
  streaming_ = true;
  slice_theta_in_deg_ = theta_in_deg;
  light_ = SphericalDirectionDeg(theta_in_deg, 0);
  next_row_ = next_column_ = 0;
  slice_samples_ = slice_clipped_ = 0;
  Reseed(kSeedSlice, theta_in_deg);
  if (exposure_.mode == ExposureMode::kFixed) {
    slice_exposure_ = {exposure_.exposure_ms, 0};
  } else if (exposure_.mode == ExposureMode::kAutoPerSlice) {
    double brightest = 0;
    for (std::size_t row = 0; row < geometry_.rows; ++row)
      brightest = std::max(brightest, MaxOf(RowRates(row, nullptr)));
    slice_exposure_ = AutoExposure(brightest);
  }
  Send(MessageType::kSliceBegin,
       EncodeSliceBegin({theta_in_deg, geometry_.rows, geometry_.columns}));
}

std::array<double, 3> SimulatedFirmware::RowRates(std::size_t row,
                                                  std::vector<std::array<double, 3>>* rates) const {
  const InstrumentModel& m = config_.model;
  const double theta_out = DegToRad(geometry_.ThetaOutDeg(row));
  const double sin_theta = std::sin(theta_out), cos_theta = std::cos(theta_out);
  std::array<double, 3> brightest{};
  if (rates) rates->resize(geometry_.columns);
  for (std::size_t col = 0; col < geometry_.columns; ++col) {
    const Vec3 view{sin_theta * column_cos_phi_[col], sin_theta * column_sin_phi_[col], cos_theta};
    const Rgb f = config_.sample->Eval(light_, view);
    std::array<double, 3> rate{};
    for (int c = 0; c < 3; ++c) {
      rate[c] = m.responsivity_counts_per_ms[c] * f[c] * light_.z;
      brightest[c] = std::max(brightest[c], rate[c]);
    }
    if (rates) (*rates)[col] = rate;
  }
  return brightest;
}

SimulatedFirmware::Exposure SimulatedFirmware::AutoExposure(double brightest_rate) const {
  const InstrumentModel& m = config_.model;
  const double dark = config_.noise_level * MaxOf(m.dark_offset_counts);
  double t = m.max_exposure_ms;
  if (brightest_rate > 0)
    t = m.autorange_target_fraction * std::max(0.0, m.adc_full_scale_counts - dark) /
        brightest_rate;
  // The least attenuating filter that keeps the exposure at or above the minimum.
  std::uint8_t nd = 0;
  while (t / static_cast<double>(m.nd_transmittance[nd]) < m.min_exposure_ms &&
         nd + 1u < m.nd_transmittance.size())
    ++nd;
  t /= static_cast<double>(m.nd_transmittance[nd]);
  return {static_cast<float>(std::clamp(t, m.min_exposure_ms, m.max_exposure_ms)), nd};
}

SimulatedFirmware::Reading SimulatedFirmware::Read(const std::array<double, 3>& rate,
                                                   Exposure exposure, int frames) {
  const InstrumentModel& m = config_.model;
  const double s = config_.noise_level;
  const double full = m.adc_full_scale_counts;
  const double sqrt_frames = std::sqrt(frames);
  Reading r;
  for (int c = 0; c < 3; ++c) {
    // The light the detector integrates: exposure time × filter transmittance (the same
    // float32 numbers the host multiplies).
    const double signal = static_cast<double>(exposure.ms) *
                          static_cast<double>(m.nd_transmittance[exposure.nd]) * rate[c];
    const double mean = signal + s * m.dark_offset_counts[c];
    if (s == 0) {  // ideal detector
      r.counts[c] = static_cast<float>(mean);
      continue;
    }
    const double sigma =
        s * std::sqrt(m.read_noise_counts * m.read_noise_counts +
                      m.conversion_gain_counts_per_electron * std::max(0.0, signal));
    if (mean + 6 * sigma < full && mean - 6 * sigma > 0) {
      // No frame can clip (beyond 6σ the Gaussian model is not meant to be exact), so the mean
      // of the frames is drawn directly.
      r.counts[c] = static_cast<float>(mean + sigma / sqrt_frames * normal_(rng_));
      continue;
    }
    double sum = 0;
    for (int i = 0; i < frames; ++i) {
      double x = mean + sigma * normal_(rng_);
      if (x >= full) {
        x = full;
        r.clipped |= static_cast<std::uint8_t>(1u << c);
      }
      sum += std::max(x, 0.0);
    }
    r.counts[c] = static_cast<float>(sum / frames);
  }
  return r;
}

void SimulatedFirmware::PrepareRow(std::size_t row) {
  if (config_.pace_ms_per_row > 0)
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(config_.pace_ms_per_row));
  std::vector<std::array<double, 3>> rates;
  const std::array<double, 3> brightest = RowRates(row, &rates);
  row_exposure_ = exposure_.mode == ExposureMode::kAutoPerRow ? AutoExposure(MaxOf(brightest))
                                                              : slice_exposure_;
  const int frames = config_.model.frames_per_reading;
  row_readings_.resize(rates.size());
  for (std::size_t col = 0; col < rates.size(); ++col) {
    row_readings_[col] = Read(rates[col], row_exposure_, frames);
    if (row_readings_[col].clipped != 0) {
      ++slice_clipped_;
      clip_log_.push_back({slice_theta_in_deg_, static_cast<std::uint16_t>(row),
                           static_cast<std::uint16_t>(col), row_readings_[col].clipped});
    }
  }
}

void SimulatedFirmware::ProduceStreamFrame() {
  if (next_row_ >= geometry_.rows) {
    streaming_ = false;
    Send(MessageType::kSliceEnd,
         EncodeSliceEnd({slice_theta_in_deg_, slice_samples_, slice_clipped_}));
    return;
  }
  if (next_column_ == 0) PrepareRow(next_row_);
  const std::size_t n = std::min(kMaxSamplesPerRowFrame, geometry_.columns - next_column_);
  RowData data;
  data.row = static_cast<std::uint16_t>(next_row_);
  data.first_column = static_cast<std::uint16_t>(next_column_);
  data.exposure_ms = row_exposure_.ms;
  data.nd_index = row_exposure_.nd;
  data.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Reading& r = row_readings_[next_column_ + i];
    data.samples[i] = {r.counts, r.clipped};
  }
  slice_samples_ += static_cast<std::uint32_t>(n);
  next_column_ += n;
  if (next_column_ == geometry_.columns) {
    ++next_row_;
    next_column_ = 0;
  }
  Send(MessageType::kRowData, EncodeRowData(data));
}

std::map<std::string, std::string> SimulatedCaptureSettings(const std::string& device,
                                                            const std::string& material,
                                                            const SimulatorConfig& config,
                                                            const CaptureGeometry& geometry,
                                                            const std::string& exposure) {
  return {{"device", device},
          {"material", material},
          {"noise_level", ShortNumberText(config.noise_level)},
          {"seed", std::to_string(config.seed)},
          {"theta_out_max_deg", ShortNumberText(geometry.theta_out_max_deg)},
          {"theta_out_step_deg", ShortNumberText(geometry.theta_out_step_deg)},
          {"phi_out_step_deg", ShortNumberText(geometry.phi_out_step_deg)},
          {"exposure", exposure}};
}

}  // namespace brdf::device
