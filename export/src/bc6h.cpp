#include "brdf/exporter/bc6h.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/parallel.h"

namespace brdf::exporter {
namespace {

// ---- The format (ARB_texture_compression_bptc, BPTC_FLOAT) ---------------------------------

struct ModeInfo {
  int number;  // the mode field's value
  int subsets;
  bool transformed;
  int epb;                   // endpoint bits
  std::array<int, 3> delta;  // bits of the transformed endpoints per channel (= epb if raw)
  // Table.F: the block's bits from bit 0 up; two-subset modes end with the partition d[4:0].
  const char* layout;
};

constexpr std::array<ModeInfo, 14> kModes = {{
    {0,
     2,
     true,
     10,
     {5, 5, 5},
     "m[1:0],g2[4],b2[4],b3[4],r0[9:0],g0[9:0],b0[9:0],r1[4:0],g3[4],g2[3:0],g1[4:0],b3[0],"
     "g3[3:0],b1[4:0],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3],d[4:0]"},
    {1,
     2,
     true,
     7,
     {6, 6, 6},
     "m[1:0],g2[5],g3[4],g3[5],r0[6:0],b3[0],b3[1],b2[4],g0[6:0],b2[5],b3[2],g2[4],b0[6:0],"
     "b3[3],b3[5],b3[4],r1[5:0],g2[3:0],g1[5:0],g3[3:0],b1[5:0],b2[3:0],r2[5:0],r3[5:0],d[4:0]"},
    {2,
     2,
     true,
     11,
     {5, 4, 4},
     "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[4:0],r0[10],g2[3:0],g1[3:0],g0[10],b3[0],g3[3:0],"
     "b1[3:0],b0[10],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3],d[4:0]"},
    {6,
     2,
     true,
     11,
     {4, 5, 4},
     "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[3:0],r0[10],g3[4],g2[3:0],g1[4:0],g0[10],g3[3:0],"
     "b1[3:0],b0[10],b3[1],b2[3:0],r2[3:0],b3[0],b3[2],r3[3:0],g2[4],b3[3],d[4:0]"},
    {10,
     2,
     true,
     11,
     {4, 4, 5},
     "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[3:0],r0[10],b2[4],g2[3:0],g1[3:0],g0[10],b3[0],"
     "g3[3:0],b1[4:0],b0[10],b2[3:0],r2[3:0],b3[1],b3[2],r3[3:0],b3[4],b3[3],d[4:0]"},
    {14,
     2,
     true,
     9,
     {5, 5, 5},
     "m[4:0],r0[8:0],b2[4],g0[8:0],g2[4],b0[8:0],b3[4],r1[4:0],g3[4],g2[3:0],g1[4:0],b3[0],"
     "g3[3:0],b1[4:0],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3],d[4:0]"},
    {18,
     2,
     true,
     8,
     {6, 5, 5},
     "m[4:0],r0[7:0],g3[4],b2[4],g0[7:0],b3[2],g2[4],b0[7:0],b3[3],b3[4],r1[5:0],g2[3:0],"
     "g1[4:0],b3[0],g3[3:0],b1[4:0],b3[1],b2[3:0],r2[5:0],r3[5:0],d[4:0]"},
    {22,
     2,
     true,
     8,
     {5, 6, 5},
     "m[4:0],r0[7:0],b3[0],b2[4],g0[7:0],g2[5],g2[4],b0[7:0],g3[5],b3[4],r1[4:0],g3[4],"
     "g2[3:0],g1[5:0],g3[3:0],b1[4:0],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3],d[4:0]"},
    {26,
     2,
     true,
     8,
     {5, 5, 6},
     "m[4:0],r0[7:0],b3[1],b2[4],g0[7:0],b2[5],g2[4],b0[7:0],b3[5],b3[4],r1[4:0],g3[4],"
     "g2[3:0],g1[4:0],b3[0],g3[3:0],b1[5:0],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3],d[4:0]"},
    {30,
     2,
     false,
     6,
     {6, 6, 6},
     "m[4:0],r0[5:0],g3[4],b3[0],b3[1],b2[4],g0[5:0],g2[5],b2[5],b3[2],g2[4],b0[5:0],g3[5],"
     "b3[3],b3[5],b3[4],r1[5:0],g2[3:0],g1[5:0],g3[3:0],b1[5:0],b2[3:0],r2[5:0],r3[5:0],d[4:0]"},
    {3, 1, false, 10, {10, 10, 10}, "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[9:0],g1[9:0],b1[9:0]"},
    {7,
     1,
     true,
     11,
     {9, 9, 9},
     "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[8:0],r0[10],g1[8:0],g0[10],b1[8:0],b0[10]"},
    {11,
     1,
     true,
     12,
     {8, 8, 8},
     "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[7:0],r0[10:11],g1[7:0],g0[10:11],b1[7:0],b0[10:11]"},
    {15,
     1,
     true,
     16,
     {4, 4, 4},
     "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[3:0],r0[10:15],g1[3:0],g0[10:15],b1[3:0],b0[10:15]"},
}};

// The first 32 two-subset partitions of Table.P2: bit t set = texel t in subset 1.
constexpr std::array<std::uint16_t, 32> kPartitions = {
    0xcccc, 0x8888, 0xeeee, 0xecc8, 0xc880, 0xfeec, 0xfec8, 0xec80, 0xc800, 0xffec, 0xfe80,
    0xe800, 0xffe8, 0xff00, 0xfff0, 0xf000, 0xf710, 0x008e, 0x7100, 0x08ce, 0x008c, 0x7310,
    0x3100, 0x8cce, 0x088c, 0x3110, 0x6666, 0x366c, 0x17e8, 0x0ff0, 0x718e, 0x399c};
// Table.A2: the anchor texel of subset 1.
constexpr std::array<std::uint8_t, 32> kAnchor2 = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                                                   15, 15, 15, 15, 15, 15, 2,  8,  2,  2,  8,
                                                   8,  15, 2,  8,  2,  2,  8,  8,  2,  2};
constexpr std::array<int, 16> kWeights4 = {0,  4,  9,  13, 17, 21, 26, 30,
                                           34, 38, 43, 47, 51, 55, 60, 64};
constexpr std::array<int, 8> kWeights3 = {0, 9, 18, 27, 37, 46, 55, 64};
// Slots of one channel of a palette in TryMode: 16 entries, one slot before, two after.
constexpr int kPaletteSlots = 19;

// For every weight 0..64, the index whose table weight is nearest (the encoder's first guess).
template <std::size_t N>
constexpr std::array<std::uint8_t, 65> NearestWeightIndex(const std::array<int, N>& weights) {
  std::array<std::uint8_t, 65> out{};
  for (int w = 0; w <= 64; ++w) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < N; ++k) {
      const int d = weights[k] - w, db = weights[best] - w;
      if (d * d < db * db) best = k;
    }
    out[w] = static_cast<std::uint8_t>(best);
  }
  return out;
}
constexpr std::array<std::uint8_t, 65> kNearest4 = NearestWeightIndex(kWeights4);
constexpr std::array<std::uint8_t, 65> kNearest3 = NearestWeightIndex(kWeights3);

// Variables of the layout strings: m = 0, endpoint e channel c = 1 + 3e + c, d = 13.
constexpr int kVarMode = 0, kVarPartition = 13, kVarCount = 14;
struct BitSource {
  std::uint8_t var, bit;
};
// `count` bits of a variable from bit `first` up, in block order (a run of BitSources).
struct BitRun {
  std::uint8_t var, first, count;
};
struct Mode {
  ModeInfo info;
  std::vector<BitSource> bits;  // one entry per header bit, in block order
  std::vector<BitRun> runs;     // the same bits, consecutive ones of a variable merged
};

std::vector<BitRun> MergeRuns(const std::vector<BitSource>& bits) {
  std::vector<BitRun> runs;
  for (const BitSource& b : bits) {
    if (!runs.empty() && runs.back().var == b.var && runs.back().first + runs.back().count == b.bit)
      ++runs.back().count;
    else
      runs.push_back({b.var, b.bit, 1});
  }
  return runs;
}

int VariableOf(std::string_view name) {
  if (name == "m") return kVarMode;
  if (name == "d") return kVarPartition;
  const int channel = name[0] == 'r' ? 0 : name[0] == 'g' ? 1 : 2;
  return 1 + 3 * (name[1] - '0') + channel;
}

// Expands a layout string: v[a:b] moves bits into v's bits b, b∓1, …, a in block order (a ≥ b
// counts up from b; a < b is the specification's reversed form and counts down from b).
std::vector<BitSource> ParseLayout(std::string_view layout) {
  std::vector<BitSource> bits;
  while (!layout.empty()) {
    const std::size_t open = layout.find('['), close = layout.find(']');
    const int var = VariableOf(layout.substr(0, open));
    const std::string_view range = layout.substr(open + 1, close - open - 1);
    const std::size_t colon = range.find(':');
    const int a = std::stoi(std::string(range.substr(0, colon)));
    const int b =
        colon == std::string_view::npos ? a : std::stoi(std::string(range.substr(colon + 1)));
    const int step = a >= b ? 1 : -1;
    for (int bit = b;; bit += step) {
      bits.push_back({static_cast<std::uint8_t>(var), static_cast<std::uint8_t>(bit)});
      if (bit == a) break;
    }
    layout.remove_prefix(std::min(layout.size(), close + 2));  // "]," or "]"
  }
  return bits;
}

struct Tables {
  std::array<Mode, 14> modes;
  std::array<int, 32> index_of_number;  // mode number → index in modes, −1 reserved
  Tables() {
    index_of_number.fill(-1);
    for (std::size_t i = 0; i < kModes.size(); ++i) {
      modes[i].info = kModes[i];
      modes[i].bits = ParseLayout(kModes[i].layout);
      modes[i].runs = MergeRuns(modes[i].bits);
      index_of_number[kModes[i].number] = static_cast<int>(i);
    }
  }
};
const Tables& GetTables() {
  static const Tables tables;
  return tables;
}

int ModeNumberOf(const std::uint8_t* block) {
  return (block[0] & 3) < 2 ? block[0] & 3 : block[0] & 31;
}

int Unquantize(int x, int epb) {
  if (epb >= 15) return x;
  if (x == 0) return 0;
  if (x == (1 << epb) - 1) return 0xFFFF;
  return ((x << 16) + 0x8000) >> epb;
}

int SignExtend(int v, int bits) {
  const int sign = 1 << (bits - 1);
  return (v & (sign - 1)) - (v & sign);
}

int Interpolate(int a, int b, int w) { return ((64 - w) * a + w * b + 32) >> 6; }
int FinishUnquantize(int c) { return (c * 31) >> 6; }

bool IsAnchor(int texel, int subsets, int partition) {
  return texel == 0 || (subsets == 2 && texel == kAnchor2[partition]);
}

// ---- Encoder -------------------------------------------------------------------------------

// One block's input in the two domains the encoder works in: h, the value as a continuous
// half-float bit pattern (what the decoded half should equal), and t = (h + 0.5)·64/31, the
// interpolated value c whose (c·31) >> 6 is h.
//
// w weighs a channel's squared error in half steps by what it costs in the certified metric
// (brdf/exporter/metadata.h: e = max_c |d_c − r_c| / S, S = max(max_c r_c, 10^−4·R, 2^−14)).
// One half step of a normal half x is x·ln2/1024 (of a denormal, 2^−24, the same as a normal
// x of 2^−14/ln2), so an error of Δ steps in channel c costs Δ·max(x_c, 2^−14/ln2)·ln2/1024/S:
// w_c = (max(x_c, 2^−14/ln2) / S)². The colour's largest channel has weight 1; a minor
// channel, or a texel far below the LUT's dark floor 10^−4·R, counts for what it costs.
struct BlockInput {
  float h[16][3];
  float t[16][3];
  float w[16][3];
  float r[16][3];   // √w: a channel's half steps in half steps of the texel's largest channel
  float hs[3][16];  // h by channel
  double wd[16][4], td[16][4];  // w and t as doubles (exact), lane 3 zero: the refit's inputs
};

// Four floats, four int32 and four doubles as one value (GCC/Clang vector extensions: the
// lanes are computed one by one as scalars would be, on SSE2 two or four at a time).
using F4 = float __attribute__((vector_size(16)));
using I4 = std::int32_t __attribute__((vector_size(16)));
using D4 = double __attribute__((vector_size(32)));

float ContinuousHalf(float x) {
  if (!(x > 0.0f)) return 0.0f;
  if (x >= kBc6hMaxValue) return 31743.0f;           // 0x7BFF
  if (x < 6.103515625e-05f) return x * 16777216.0f;  // denormals: steps of 2^−24
  // x = (1 + m/2^23)·2^(E − 127): the half pattern (E − 127 + 15)·1024 + m/2^13, unrounded.
  const std::uint32_t f = std::bit_cast<std::uint32_t>(x);
  return static_cast<float>((static_cast<int>(f >> 23) - 112) * 1024) +
         static_cast<float>(f & 0x7FFFFFu) * (1.0f / 8192.0f);
}

struct Endpoints {
  float e[2][2][3];  // subset, end, channel (interp domain t)
};

int QuantizeEndpoint(float value, int epb) {
  const float v = std::clamp(value, 0.0f, 65535.0f);
  if (epb >= 15) return static_cast<int>(v + 0.5f);
  // Inside the range Unquantize(q) is the centre of [q, q + 1)·2^(16 − EPB), so the bucket is
  // nearest; 0 and 2^EPB − 1 map to the range's ends instead, so look next to them.
  const int max = (1 << epb) - 1;
  const int q = std::min(static_cast<int>(v * (1.0f / static_cast<float>(1 << (16 - epb)))), max);
  if (q > 1 && q < max - 1) return q;
  int best = q;
  float best_d = std::abs(static_cast<float>(Unquantize(q, epb)) - v);
  for (int c : {q - 1, q + 1}) {
    if (c < 0 || c > max) continue;
    const float d = std::abs(static_cast<float>(Unquantize(c, epb)) - v);
    if (d < best_d) best = c, best_d = d;
  }
  return best;
}

// The endpoints quantized to one precision, each on first use (modes of the same precision
// share them; a mode whose first delta does not fit needs only a few).
struct QuantizedEnds {
  explicit QuantizedEnds(const Endpoints& e) : ends(e) {}
  const Endpoints& ends;
  int epb = -1;
  int q[4][3] = {};
  int Get(int e, int c) {
    if (q[e][c] < 0) q[e][c] = QuantizeEndpoint(ends.e[e / 2][e % 2][c], epb);
    return q[e][c];
  }
  void SetPrecision(int bits) {
    if (bits == epb) return;
    epb = bits;
    std::memset(q, -1, sizeof(q));
  }
};

// The best candidate so far, kept as its fields: the block is packed once, at the end.
struct Encoded {
  float error = std::numeric_limits<float>::infinity();  // Σ w·(decoded − h)², candidates' order
  float plain_error = 0.0f;  // Σ (decoded − h)² in half steps, unweighted (the two-subset gate)
  float worst = 0.0f;  // max √w·|decoded − h|: half steps of each texel's largest channel
                       // (one-subset candidates; infinity for two subsets)
  const Mode* mode = nullptr;
  int partition = 0;
  int fields[4][3] = {};
  std::array<int, 16> indices{};
};

// Appends the low `count` (≤ 32) bits of `value` at bit `pos` of the block held as two 64-bit
// words (bit i of the block is bit i % 64 of word i / 64).
void PutBits(std::uint64_t (&words)[2], int& pos, std::uint32_t value, int count) {
  const std::uint64_t v = value & ((std::uint64_t{1} << count) - 1);
  const int shift = pos & 63;
  words[pos >> 6] |= v << shift;
  if (shift + count > 64) words[1] |= v >> (64 - shift);
  pos += count;
}

Bc6hBlock Pack(const Mode& mode, int partition, const int (&fields)[4][3],
               const std::array<int, 16>& indices) {
  int vars[kVarCount] = {};
  vars[kVarMode] = mode.info.number;
  vars[kVarPartition] = partition;
  for (int e = 0; e < 2 * mode.info.subsets; ++e)
    for (int c = 0; c < 3; ++c) vars[1 + 3 * e + c] = fields[e][c];
  std::uint64_t words[2] = {};
  int pos = 0;
  for (const BitRun& r : mode.runs)
    PutBits(words, pos, static_cast<std::uint32_t>(vars[r.var]) >> r.first, r.count);
  const int index_bits = mode.info.subsets == 2 ? 3 : 4;
  for (int t = 0; t < 16; ++t)
    PutBits(words, pos, static_cast<std::uint32_t>(indices[t]),
            index_bits - (IsAnchor(t, mode.info.subsets, partition) ? 1 : 0));
  Bc6hBlock block{};
  for (int i = 0; i < 16; ++i) block[i] = static_cast<std::uint8_t>(words[i >> 3] >> (8 * (i & 7)));
  return block;
}

// Quantizes the endpoints for `mode`, picks each texel's best index and refits the endpoints
// to the indices by least squares, `refinements` times; the best candidate seen goes into
// `best`. A refit whose quantized endpoints equal the previous pass's would repeat that pass
// exactly (same palette, indices and error, so never strictly better): the loop stops there.
// kSubsets is the mode's subset count (a template argument, so the one-subset search has no
// partition lookups). Lanes of F4 and D4 hold independent numbers, each formed by the same
// operations in the same order as a scalar loop would (no sums across lanes).
template <int kSubsets>
void TryMode(const Mode& mode, int partition, Endpoints ends, QuantizedEnds& first,
             const BlockInput& in, int refinements, Encoded& best) {
  const ModeInfo& info = mode.info;
  constexpr int subsets = kSubsets;
  const std::uint16_t mask = subsets == 2 ? kPartitions[partition] : 0;
  // Texel 0 is always an anchor; the second subset's anchor (none for one subset).
  const int anchor1 = subsets == 2 ? kAnchor2[partition] : 0;
  constexpr int levels = subsets == 2 ? 8 : 16;
  const int* weights = subsets == 2 ? kWeights3.data() : kWeights4.data();
  const int wrap = (1 << info.epb) - 1;
  int previous_q[4][3];
  for (int pass = 0; pass <= refinements; ++pass) {
    int q[4][3], fields[4][3];
    if (pass == 0) first.SetPrecision(info.epb);  // `ends` as given: quantized once
    for (int s = 0; s < subsets; ++s)
      for (int end = 0; end < 2; ++end)
        for (int c = 0; c < 3; ++c)
          q[2 * s + end][c] =
              pass == 0 ? first.Get(2 * s + end, c) : QuantizeEndpoint(ends.e[s][end][c], info.epb);
    for (int c = 0; c < 3; ++c) {
      fields[0][c] = q[0][c];
      for (int e = 1; e < 2 * subsets; ++e) {
        if (!info.transformed) {
          fields[e][c] = q[e][c];
          continue;
        }
        // The delta modulo 2^EPB as a signed number, clamped to what the field holds.
        int d = (q[e][c] - q[0][c]) & wrap;
        if (d > wrap / 2) d -= wrap + 1;
        const int limit = 1 << (info.delta[c] - 1);
        d = std::clamp(d, -limit, limit - 1);
        q[e][c] = (q[0][c] + d) & wrap;
        fields[e][c] = d & ((1 << info.delta[c]) - 1);
      }
    }
    if (pass > 0 && std::memcmp(q, previous_q, sizeof(int) * 3 * 2 * subsets) == 0) break;
    std::memcpy(previous_q, q, sizeof(int) * 3 * 2 * subsets);
    // Decoded palettes, exactly as the decoder computes them, as floats by channel: entry k of
    // subset s, channel c is pal[s][c][k + 1] (one slot of padding before entry 0 and two
    // after the last, so a texel's three neighbouring entries are one load of four lanes).
    float pal[subsets][3][kPaletteSlots];
    for (int s = 0; s < subsets; ++s)
      for (int c = 0; c < 3; ++c) {
        const int a = Unquantize(q[2 * s][c], info.epb), b = Unquantize(q[2 * s + 1][c], info.epb);
        pal[s][c][0] = pal[s][c][levels + 1] = pal[s][c][levels + 2] = 0.0f;  // never compared
        for (int k = 0; k < levels; ++k)
          pal[s][c][k + 1] = static_cast<float>(FinishUnquantize(Interpolate(a, b, weights[k])));
      }
    std::array<int, 16> indices{};
    float error = 0.0f, plain_error = 0.0f;
    // On the last pass no refit follows, so the candidate matters only if its error ends below
    // best.error; the sum of non-negative terms never decreases, so once it reaches best.error
    // the remaining texels cannot change the outcome and are skipped.
    const bool last_pass = pass == refinements;
    // Each texel's index: its projection on the subset's decoded segment gives a weight, the
    // nearest weights' entries are compared exactly (the palette is monotonic per channel).
    const std::uint8_t* nearest = subsets == 2 ? kNearest3.data() : kNearest4.data();
    float dir[2][3], inv_len2[2];
    for (int s = 0; s < subsets; ++s) {
      float len2 = 0.0f;
      for (int c = 0; c < 3; ++c) {
        dir[s][c] = pal[s][c][levels] - pal[s][c][1];
        len2 += dir[s][c] * dir[s][c];
      }
      inv_len2[s] = len2 > 0.0f ? 64.0f / len2 : 0.0f;
    }
    // The weights of all 16 texels, four texels a vector: lane i of group g is texel 4g + i,
    // its subset's origin, direction and 1/length² chosen per lane (by bits, exactly).
    alignas(16) std::int32_t nearest_weight[16];
    for (int g = 0; g < 4; ++g) {
      I4 lane_subset = {};
      if constexpr (subsets == 2)
        lane_subset = I4{(mask >> (4 * g)) & 1, (mask >> (4 * g + 1)) & 1,
                         (mask >> (4 * g + 2)) & 1, (mask >> (4 * g + 3)) & 1};
      const I4 second = -lane_subset;  // all bits set in the lanes of subset 1
      const auto pick = [&](float v0, float v1) {
        const I4 a = std::bit_cast<I4>(F4{v0, v0, v0, v0}),
                 b = std::bit_cast<I4>(F4{v1, v1, v1, v1});
        return std::bit_cast<F4>((a & ~second) | (b & second));
      };
      F4 p = {};
      for (int c = 0; c < 3; ++c) {
        F4 h;
        std::memcpy(&h, &in.hs[c][4 * g], sizeof(h));
        const F4 origin = pick(pal[0][c][1], pal[subsets - 1][c][1]);
        const F4 direction = pick(dir[0][c], dir[subsets - 1][c]);
        p += (h - origin) * direction;
      }
      const F4 scale = pick(inv_len2[0], inv_len2[subsets - 1]);
      I4 w = __builtin_convertvector(p * scale + 0.5f, I4);
      w = w < 0 ? 0 : w;
      w = w > 64 ? 64 : w;
      std::memcpy(&nearest_weight[4 * g], &w, sizeof(w));
    }
    for (int t = 0; t < 16; ++t) {
      const int s = subsets == 2 ? (mask >> t) & 1 : 0;
      const int allowed = t == 0 || (subsets == 2 && t == anchor1) ? levels / 2 : levels;
      const float* h = in.h[t];
      const float* w3 = in.w[t];
      const int centre = std::min<int>(nearest[nearest_weight[t]], allowed - 1);
      // Lane j holds entry centre − 1 + j (lane 3 and out-of-range lanes are not compared); each
      // lane's sums are formed in the order of one entry's: channel 0, 1, 2.
      F4 e2v = {}, plainv = {};
      for (int c = 0; c < 3; ++c) {
        F4 entry;
        std::memcpy(&entry, &pal[s][c][centre], sizeof(entry));
        const F4 d = entry - h[c];
        e2v += w3[c] * d * d, plainv += d * d;
      }
      float e2[4], plain[4];
      std::memcpy(e2, &e2v, sizeof(e2));
      std::memcpy(plain, &plainv, sizeof(plain));
      // Entries centre − 1, centre, centre + 1 in turn, a later one only when strictly better;
      // the centre is always in range, so a missing neighbour simply loses.
      constexpr float kMissing = std::numeric_limits<float>::infinity();
      if (centre == 0) e2[0] = kMissing;
      if (centre + 1 > allowed - 1) e2[2] = kMissing;
      int pick = e2[1] < e2[0] ? 1 : 0;
      if (e2[2] < e2[pick]) pick = 2;
      const float best_e = e2[pick], best_plain = plain[pick];
      indices[t] = centre - 1 + pick;
      error += best_e, plain_error += best_plain;
      if (last_pass && !(error < best.error)) break;
    }
    if (error < best.error) {
      best.error = error;
      best.plain_error = plain_error;
      best.mode = &mode;
      best.partition = partition;
      std::memcpy(best.fields, fields, sizeof(fields));
      best.indices = indices;
      // The decoder's texels are these palette entries, so this is the decoded block's error.
      // Only the one-subset search's early exit reads it; two-subset candidates leave it at
      // infinity (not computed).
      float worst = subsets == 1 ? 0.0f : std::numeric_limits<float>::infinity();
      if constexpr (subsets == 1)
        for (int t = 0; t < 16; ++t)
          for (int c = 0; c < 3; ++c)
            worst = std::max(worst, in.r[t][c] * std::abs(pal[0][c][indices[t] + 1] - in.h[t][c]));
      best.worst = worst;
    }
    // No refit can beat an exact candidate.
    if (pass == refinements || error == 0.0f) break;
    // Weighted least squares per subset and channel: min Σ w·((1 − α)a + αb − t)² over the
    // texels (the weights differ per channel, so each channel has its own 2 × 2 system).
    // One pass over the texels; each subset's sums still take its texels in ascending order.
    // Lane c of the D4 sums is channel c (lane 3 is padding).
    D4 aa[2] = {}, ab[2] = {}, bb[2] = {}, at[2] = {}, bt[2] = {}, wsum[2] = {}, wt[2] = {};
    for (int t = 0; t < 16; ++t) {
      const int s = subsets == 2 ? (mask >> t) & 1 : 0;
      const double alpha = weights[indices[t]] / 64.0, beta = 1.0 - alpha;
      D4 w, x;
      std::memcpy(&w, in.wd[t], sizeof(w));
      std::memcpy(&x, in.td[t], sizeof(x));
      const D4 wa = w * alpha, wb = w * beta;
      aa[s] += wb * beta, ab[s] += wa * beta, bb[s] += wa * alpha;
      at[s] += wb * x, bt[s] += wa * x;
      wsum[s] += w, wt[s] += w * x;
    }
    for (int s = 0; s < subsets; ++s)
      for (int c = 0; c < 3; ++c) {
        // The determinant relative to (Σw)²: all texels on one index leaves only the mean.
        const double det = aa[s][c] * bb[s][c] - ab[s][c] * ab[s][c];
        if (!(wsum[s][c] > 0.0) || std::abs(det) < 1e-9 * wsum[s][c] * wsum[s][c]) {
          const double mean = wsum[s][c] > 0.0 ? wt[s][c] / wsum[s][c] : 0.0;
          ends.e[s][0][c] = ends.e[s][1][c] = static_cast<float>(mean);
        } else {
          ends.e[s][0][c] = static_cast<float>((bb[s][c] * at[s][c] - ab[s][c] * bt[s][c]) / det);
          ends.e[s][1][c] = static_cast<float>((aa[s][c] * bt[s][c] - ab[s][c] * at[s][c]) / det);
        }
      }
  }
}

// Principal axis of a 3 × 3 covariance (power iteration from its largest column).
std::array<double, 3> PrincipalAxis(const double (&cov)[3][3]) {
  int start = 0;
  for (int c = 1; c < 3; ++c)
    if (cov[c][c] > cov[start][start]) start = c;
  std::array<double, 3> v = {cov[0][start], cov[1][start], cov[2][start]};
  for (int it = 0; it < 8; ++it) {
    std::array<double, 3> w{};
    for (int r = 0; r < 3; ++r) w[r] = cov[r][0] * v[0] + cov[r][1] * v[1] + cov[r][2] * v[2];
    const double norm = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (!(norm > 1e-30)) break;
    for (int r = 0; r < 3; ++r) v[r] = w[r] / norm;
  }
  const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(norm > 1e-30)) return {0.57735026918962584, 0.57735026918962584, 0.57735026918962584};
  return {v[0] / norm, v[1] / norm, v[2] / norm};
}

// Endpoints of subset s (texels where ((mask >> t) & 1) == s) along its principal axis, end 0
// on the side of the subset's anchor texel so that its index fits the shortened field.
void FitLine(const BlockInput& in, std::uint16_t mask, int s, int anchor, float (&ends)[2][3]) {
  // The subset's texels as bits, visited in ascending order as a loop over all 16 would.
  const unsigned members = s == 1 ? mask : ~static_cast<unsigned>(mask) & 0xFFFFu;
  double mean[3] = {};
  for (unsigned bits = members; bits != 0; bits &= bits - 1) {
    const float* x = in.t[std::countr_zero(bits)];
    for (int c = 0; c < 3; ++c) mean[c] += x[c];
  }
  for (double& m : mean) m /= std::max(std::popcount(members), 1);
  // Symmetric: the six sums above the diagonal, mirrored (the products are the same numbers).
  double c00 = 0, c01 = 0, c02 = 0, c11 = 0, c12 = 0, c22 = 0;
  for (unsigned bits = members; bits != 0; bits &= bits - 1) {
    const float* x = in.t[std::countr_zero(bits)];
    const double d0 = x[0] - mean[0], d1 = x[1] - mean[1], d2 = x[2] - mean[2];
    c00 += d0 * d0, c01 += d0 * d1, c02 += d0 * d2;
    c11 += d1 * d1, c12 += d1 * d2, c22 += d2 * d2;
  }
  const double cov[3][3] = {{c00, c01, c02}, {c01, c11, c12}, {c02, c12, c22}};
  const std::array<double, 3> axis = PrincipalAxis(cov);
  double lo = 0.0, hi = 0.0, anchor_p = 0.0;
  for (unsigned bits = members; bits != 0; bits &= bits - 1) {
    const int t = std::countr_zero(bits);
    double p = 0.0;
    for (int c = 0; c < 3; ++c) p += (in.t[t][c] - mean[c]) * axis[c];
    lo = std::min(lo, p), hi = std::max(hi, p);
    if (t == anchor) anchor_p = p;
  }
  if (anchor_p - lo > hi - anchor_p) std::swap(lo, hi);
  for (int c = 0; c < 3; ++c) {
    ends[0][c] = static_cast<float>(mean[c] + lo * axis[c]);
    ends[1][c] = static_cast<float>(mean[c] + hi * axis[c]);
  }
}

// Search effort: least-squares refinements per candidate, partitions tried in the two-subset
// modes, modes tried per endpoint set, and the factor of the one-subset error a two-line
// estimate must stay under to try two subsets (benchmarks in docs/benchmarks/bc6h.md).
// BRDF_BC6H_REFERENCE_SEARCH (a build for bench/bc6h/reference_search.sh only) makes the
// search near exhaustive: every partition, every mode that holds the endpoints, 4
// refinements, no early exit and no gate, to show what the format allows.
#ifdef BRDF_BC6H_REFERENCE_SEARCH
constexpr bool kReferenceSearch = true;
constexpr int kRefinements = 4;
constexpr int kPartitionsTried = 32;
constexpr int kModesTried = 14;
#else
constexpr bool kReferenceSearch = false;
constexpr int kRefinements = 1;
constexpr int kPartitionsTried = 2;
constexpr int kModesTried = 1;
#endif
constexpr double kTwoSubsetGain = 1.0;

// Estimated squared error of a two-line fit for every partition: per subset the scatter off
// its principal axis plus the quantization of 8 levels along it (a uniform spread's variance
// /49), from running sums. Returns partitions ranked best first.
std::array<int, kPartitionsTried> RankPartitions(const BlockInput& in, double& best_estimate) {
  double total[9] = {};
  double texel[16][9];
  for (int t = 0; t < 16; ++t) {
    const float* x = in.t[t];
    double* p = texel[t];
    p[0] = x[0], p[1] = x[1], p[2] = x[2];
    p[3] = x[0] * double(x[0]), p[4] = x[0] * double(x[1]), p[5] = x[0] * double(x[2]);
    p[6] = x[1] * double(x[1]), p[7] = x[1] * double(x[2]), p[8] = x[2] * double(x[2]);
    for (int i = 0; i < 9; ++i) total[i] += p[i];
  }
  std::array<double, 3> axis;
  {
    double cov[3][3];
    const int k[3][3] = {{3, 4, 5}, {4, 6, 7}, {5, 7, 8}};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov[r][c] = total[k[r][c]] - total[r] * total[c] / 16.0;
    axis = PrincipalAxis(cov);
  }
  // One subset's estimate from its running sums m (x, y, z, xx, xy, xz, yy, yz, zz) of n
  // texels. Written out in scalars so the sums stay in registers; every operation is the one
  // the matrix form does, in the same order (the ranking, and so the bytes, are unchanged).
  const auto estimate = [&axis](double n, double m0, double m1, double m2, double m3, double m4,
                                double m5, double m6, double m7, double m8) {
    const double mx = m0 / n, my = m1 / n, mz = m2 / n;
    const double c00 = m3 - n * mx * mx, c01 = m4 - n * mx * my, c02 = m5 - n * mx * mz;
    const double c11 = m6 - n * my * my, c12 = m7 - n * my * mz, c22 = m8 - n * mz * mz;
    // λmax ≈ the Rayleigh quotient after one power step from the block's axis.
    const double v0 = c00 * axis[0] + c01 * axis[1] + c02 * axis[2];
    const double v1 = c01 * axis[0] + c11 * axis[1] + c12 * axis[2];
    const double v2 = c02 * axis[0] + c12 * axis[1] + c22 * axis[2];
    const double len2 = v0 * v0 + v1 * v1 + v2 * v2;
    double lambda = 0.0;
    if (len2 > 1e-30) {
      lambda += v0 * c00 * v0, lambda += v0 * c01 * v1, lambda += v0 * c02 * v2;
      lambda += v1 * c01 * v0, lambda += v1 * c11 * v1, lambda += v1 * c12 * v2;
      lambda += v2 * c02 * v0, lambda += v2 * c12 * v1, lambda += v2 * c22 * v2;
      lambda /= len2;
    }
    const double trace = std::max(0.0, c00 + c11 + c22);
    lambda = std::clamp(lambda, 0.0, trace);
    return (trace - lambda) + lambda / 49.0;
  };
  // The kPartitionsTried lowest scores so far, in order of (score, partition number): the
  // same list as sorting all 32 with lower partition numbers first on ties. A partition
  // enters only with a score strictly below the list's last once the list is full, and its
  // score is the sum of two non-negative subset estimates, so when the first one alone
  // already reaches the last score the second is not needed.
  std::array<int, kPartitionsTried> order;
  std::array<double, kPartitionsTried> kept;
  int count = 0;
  for (int part = 0; part < 32; ++part) {
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0, s8 = 0;
    int n1 = 0;
    for (unsigned bits = kPartitions[part]; bits != 0; bits &= bits - 1, ++n1) {
      const double* p = texel[std::countr_zero(bits)];
      s0 += p[0], s1 += p[1], s2 += p[2], s3 += p[3], s4 += p[4];
      s5 += p[5], s6 += p[6], s7 += p[7], s8 += p[8];
    }
    const bool full = count == kPartitionsTried;
    double est = 0.0;
    est += estimate(16 - n1, total[0] - s0, total[1] - s1, total[2] - s2, total[3] - s3,
                    total[4] - s4, total[5] - s5, total[6] - s6, total[7] - s7, total[8] - s8);
    if (full && !(est < kept[kPartitionsTried - 1])) continue;
    est += estimate(n1, s0, s1, s2, s3, s4, s5, s6, s7, s8);
    if (full && !(est < kept[kPartitionsTried - 1])) continue;
    int at = full ? kPartitionsTried - 1 : count++;
    for (; at > 0 && est < kept[at - 1]; --at) kept[at] = kept[at - 1], order[at] = order[at - 1];
    kept[at] = est, order[at] = part;
  }
  best_estimate = kept[0];
  return order;
}

// True when the endpoints' quantized deltas fit the mode's fields without clamping.
bool DeltasFit(const ModeInfo& info, QuantizedEnds& quantized) {
  if (!info.transformed) return true;
  quantized.SetPrecision(info.epb);
  const int wrap = (1 << info.epb) - 1;
  for (int c = 0; c < 3; ++c) {
    const int base = quantized.Get(0, c);
    const int limit = 1 << (info.delta[c] - 1);
    for (int e = 1; e < 2 * info.subsets; ++e) {
      int d = (quantized.Get(e, c) - base) & wrap;
      if (d > wrap / 2) d -= wrap + 1;
      if (d < -limit || d >= limit) return false;
    }
  }
  return true;
}

// Tries the kModesTried most precise modes of `subsets` subsets whose deltas hold the
// endpoints (modes are listed by endpoint precision within each kind, the raw ones last).
template <int subsets>
void TryBestModes(int partition, const Endpoints& ends, const BlockInput& in, Encoded& best) {
  static const std::array<int, 14> order = [] {
    std::array<int, 14> o{};
    for (int i = 0; i < 14; ++i) o[i] = i;
    std::stable_sort(o.begin(), o.end(),
                     [](int a, int b) { return kModes[a].epb > kModes[b].epb; });
    return o;
  }();
  const Tables& tables = GetTables();
  QuantizedEnds quantized(ends);
  int tried = 0;
  for (int i : order) {
    const Mode& mode = tables.modes[i];
    if (mode.info.subsets != subsets || !DeltasFit(mode.info, quantized)) continue;
    TryMode<subsets>(mode, partition, ends, quantized, in, kRefinements, best);
    if (++tried == kModesTried) break;
  }
}

Bc6hBlock PackBest(const Encoded& best) {
  return Pack(*best.mode, best.partition, best.fields, best.indices);
}

}  // namespace

std::uint16_t FloatToHalfUnsigned(float value) {
  if (!(value > 0.0f)) return 0;  // NaN, zero, negative
  // Positive halves order like their bit patterns, so the clamp to 65504 is a min on bits
  // (FloatToHalf gives +inf, 0x7C00, from 65520 up).
  return std::min<std::uint16_t>(FloatToHalf(value), 0x7BFF);
}

int Bc6hBlockMode(const std::uint8_t* block) { return ModeNumberOf(block); }

Bc6hHalfTexels DecodeBc6hBlock(const std::uint8_t* block) {
  Bc6hHalfTexels out{};
  const Tables& tables = GetTables();
  const int index = tables.index_of_number[ModeNumberOf(block)];
  if (index < 0) return out;  // reserved mode: black
  const Mode& mode = tables.modes[index];
  const ModeInfo& info = mode.info;
  int pos = 0;
  const auto bit = [&]() {
    const int b = (block[pos >> 3] >> (pos & 7)) & 1;
    ++pos;
    return b;
  };
  int vars[kVarCount] = {};
  for (const BitSource& s : mode.bits) vars[s.var] |= bit() << s.bit;
  const int endpoints = 2 * info.subsets;
  int e[4][3];
  for (int i = 0; i < endpoints; ++i)
    for (int c = 0; c < 3; ++c) e[i][c] = vars[1 + 3 * i + c];
  if (info.transformed) {
    const int wrap = (1 << info.epb) - 1;
    for (int i = 1; i < endpoints; ++i)
      for (int c = 0; c < 3; ++c) e[i][c] = (e[0][c] + SignExtend(e[i][c], info.delta[c])) & wrap;
  }
  for (int i = 0; i < endpoints; ++i)
    for (int c = 0; c < 3; ++c) e[i][c] = Unquantize(e[i][c], info.epb);
  const int partition = vars[kVarPartition];
  const std::uint16_t mask = info.subsets == 2 ? kPartitions[partition] : 0;
  const int index_bits = info.subsets == 2 ? 3 : 4;
  const int* weights = info.subsets == 2 ? kWeights3.data() : kWeights4.data();
  for (int t = 0; t < 16; ++t) {
    const int bits = index_bits - (IsAnchor(t, info.subsets, partition) ? 1 : 0);
    int idx = 0;
    for (int i = 0; i < bits; ++i) idx |= bit() << i;
    const int s = (mask >> t) & 1;
    for (int c = 0; c < 3; ++c)
      out[t][c] = static_cast<std::uint16_t>(
          FinishUnquantize(Interpolate(e[2 * s][c], e[2 * s + 1][c], weights[idx])));
  }
  return out;
}

Bc6hBlock EncodeBc6hBlock(const float* rgb48, float reference_max) {
  BlockInput in;
  // The metric's floor: 10^−4·R and 2^−14 (R clamped as the reference is, to [0, 65504]).
  const float reference = std::clamp(reference_max, 0.0f, kBc6hMaxValue);
  const float floor = std::max(1e-4f * reference, 6.103515625e-05f);
  constexpr float kDenormalValue = 6.103515625e-05f / 0.69314718f;  // 2^−14/ln2
  for (int t = 0; t < 16; ++t) {
    float x[3], scale = floor;
    for (int c = 0; c < 3; ++c) {
      const float v = rgb48[3 * t + c];
      x[c] = v > 0.0f ? std::min(v, kBc6hMaxValue) : 0.0f;  // NaN and negatives: 0
      scale = std::max(scale, x[c]);
    }
    for (int c = 0; c < 3; ++c) {
      in.h[t][c] = ContinuousHalf(rgb48[3 * t + c]);
      in.t[t][c] = (in.h[t][c] + 0.5f) * (64.0f / 31.0f);
      const float ratio = std::min(std::max(x[c], kDenormalValue) / scale, 1.0f);
      in.w[t][c] = ratio * ratio;
      in.r[t][c] = ratio;
      in.hs[c][t] = in.h[t][c];
      in.wd[t][c] = in.w[t][c], in.td[t][c] = in.t[t][c];
    }
    in.wd[t][3] = in.td[t][3] = 0.0;
  }
  Encoded best;
  {
    Endpoints ends{};
    FitLine(in, 0, 0, 0, ends.e[0]);
    TryBestModes<1>(0, ends, in, best);
  }
  if (!kReferenceSearch && static_cast<int>(std::ceil(best.worst)) <= kBc6hGoodEnoughHalfSteps)
    return PackBest(best);
  double estimate = 0.0;
  const std::array<int, kPartitionsTried> ranked = RankPartitions(in, estimate);
  // Scatter that no line fits (noise) stays whatever the partition: only a two-line estimate
  // below the one-subset block's error is worth the two-subset modes. The estimate is in
  // the interpolation domain, (64/31)² times the half domain of `best.error`.
  if (!kReferenceSearch &&
      estimate * (31.0 / 64.0) * (31.0 / 64.0) > kTwoSubsetGain * best.plain_error)
    return PackBest(best);
  for (int r = 0; r < kPartitionsTried; ++r) {
    const int part = ranked[r];
    Endpoints ends{};
    FitLine(in, kPartitions[part], 0, 0, ends.e[0]);
    FitLine(in, kPartitions[part], 1, kAnchor2[part], ends.e[1]);
    TryBestModes<2>(part, ends, in, best);
  }
  return PackBest(best);
}

std::uint32_t Bc6hVolume::Crc32() const { return brdf::Crc32(bytes.data(), bytes.size()); }

Bc6hVolume EncodeBc6hVolume(const float* rgb, int width, int height, int depth, int jobs) {
  for (const int d : {width, height, depth})
    if (d < 1 || d > 65536)
      throw InvalidArgument(fmt::format(
          "BC6H: texture dimensions must be in 1..65536, got {} × {} × {}", width, height, depth));
  Bc6hVolume v;
  v.width = width, v.height = height, v.depth = depth;
  v.bytes.assign(v.BlockCount() * kBc6hBlockBytes, 0);
  const int bw = v.BlocksWide(), bh = v.BlocksHigh();
  // R of the error metric: the texture's largest value as the reference holds it.
  float reference_max = 0.0f;
  const std::size_t values = static_cast<std::size_t>(width) * height * depth * 3;
  for (std::size_t i = 0; i < values; ++i)
    if (rgb[i] > reference_max) reference_max = rgb[i];  // NaN never compares greater
  // Tasks of kRowsPerTask block rows. Each block's bytes depend on its 16 texels only, so the
  // result is the same for any number of threads, and a block whose texels equal those of its
  // left or upper neighbour (flat regions, the clamped padding at the right and bottom edges)
  // takes that neighbour's bytes without encoding again.
  constexpr std::size_t kRowsPerTask = 8;
  ParallelChunks(
      static_cast<std::size_t>(bh) * depth, kRowsPerTask, ResolveJobs(jobs), nullptr,
      [&](std::size_t begin, std::size_t end) {
        // The texels of this task's previous block row, block by block (valid for row − 1).
        std::vector<float> above(static_cast<std::size_t>(bw) * 48), current(above.size());
        for (std::size_t row = begin; row < end; ++row) {
          const int z = static_cast<int>(row / bh), by = static_cast<int>(row % bh);
          const bool have_above = row > begin && by > 0;
          for (int bx = 0; bx < bw; ++bx) {
            float* texels = &current[static_cast<std::size_t>(bx) * 48];
            for (int t = 0; t < 16; ++t) {
              const int x = std::min(4 * bx + t % 4, width - 1);
              const int y = std::min(4 * by + t / 4, height - 1);
              const float* src = rgb + ((static_cast<std::size_t>(z) * height + y) * width + x) * 3;
              texels[3 * t] = src[0], texels[3 * t + 1] = src[1], texels[3 * t + 2] = src[2];
            }
            std::uint8_t* out = v.bytes.data() + v.BlockOffset(4 * bx, 4 * by, z);
            constexpr std::size_t kTexelBytes = 48 * sizeof(float);
            if (bx > 0 && std::memcmp(texels, texels - 48, kTexelBytes) == 0) {
              std::memcpy(out, out - kBc6hBlockBytes, kBc6hBlockBytes);
            } else if (have_above && std::memcmp(texels, &above[static_cast<std::size_t>(bx) * 48],
                                                 kTexelBytes) == 0) {
              std::memcpy(out, v.bytes.data() + v.BlockOffset(4 * bx, 4 * (by - 1), z),
                          kBc6hBlockBytes);
            } else {
              const Bc6hBlock block = EncodeBc6hBlock(texels, reference_max);
              std::memcpy(out, block.data(), kBc6hBlockBytes);
            }
          }
          above.swap(current);
        }
      });
  return v;
}

std::vector<float> DecodeBc6hVolume(const Bc6hVolume& v) {
  if (v.width < 1 || v.height < 1 || v.depth < 1 ||
      v.bytes.size() != v.BlockCount() * kBc6hBlockBytes)
    throw InvalidArgument(
        fmt::format("BC6H: {} bytes do not hold the {} blocks of a {} × {} × {} "
                    "texture",
                    v.bytes.size(), v.BlockCount(), v.width, v.height, v.depth));
  std::vector<float> out(static_cast<std::size_t>(v.width) * v.height * v.depth * 3);
  for (int z = 0; z < v.depth; ++z)
    for (int by = 0; by < v.BlocksHigh(); ++by)
      for (int bx = 0; bx < v.BlocksWide(); ++bx) {
        const Bc6hHalfTexels texels =
            DecodeBc6hBlock(v.bytes.data() + v.BlockOffset(4 * bx, 4 * by, z));
        for (int t = 0; t < 16; ++t) {
          const int x = 4 * bx + t % 4, y = 4 * by + t / 4;
          if (x >= v.width || y >= v.height) continue;
          float* dst = &out[((static_cast<std::size_t>(z) * v.height + y) * v.width + x) * 3];
          for (int c = 0; c < 3; ++c) dst[c] = HalfToFloat(texels[t][c]);
        }
      }
  return out;
}

}  // namespace brdf::exporter
