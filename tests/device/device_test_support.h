// Helpers shared by the device tests: library materials, a simulated instrument with a
// chosen geometry, and a whole capture through the real driver.
#pragma once

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/device/driver.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"

namespace brdf::device::testing {

inline std::string LibraryDir() { return std::string(BRDF_SOURCE_DIR) + "/data-samples/materials"; }

inline std::vector<std::string> LibraryNames() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(LibraryDir()))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

inline Material LibraryMaterial(const std::string& name) {
  return LoadMaterialFile(LibraryDir() + "/" + name + ".json");
}

// The reference instrument, optionally with coarser steps to keep a test fast.
inline SimulatorConfig Config(const Material& material, double noise, float theta_out_step_deg = 1,
                              float phi_out_step_deg = 1, std::uint64_t seed = 1) {
  SimulatorConfig c;
  c.sample = std::make_shared<AnalyticBrdf>(material);
  c.noise_level = noise;
  c.seed = seed;
  c.model.theta_out_step_deg = theta_out_step_deg;
  c.model.phi_out_step_deg = phi_out_step_deg;
  return c;
}

struct CaptureRun {
  std::vector<Slice> slices;
  Metadata metadata;
};

// Runs Capture() against `firmware`; slices delivered before a fault stay in `run->slices`.
inline Metadata RunCapture(SimulatedFirmware& firmware, CaptureRun* run,
                           std::vector<double> theta_in = {0, 20, 40, 60},
                           ExposureSetting exposure = {}) {
  LoopbackTransport link(firmware);
  Driver driver(link);
  CapturePlan plan;
  plan.theta_in_deg = std::move(theta_in);
  plan.exposure = exposure;
  plan.metadata.sample_name = "test sample";
  CaptureCallbacks callbacks;
  callbacks.on_slice = [&](const Slice& s, const SliceReport&) { run->slices.push_back(s); };
  run->metadata = Capture(driver, plan, callbacks);
  return run->metadata;
}

// A whole capture by `firmware` (θin 0, 20, 40, 60°) as a measurement.
inline Measurement CaptureMeasurement(SimulatedFirmware& firmware) {
  CaptureRun run;
  RunCapture(firmware, &run);
  Measurement meas;
  meas.metadata = run.metadata;
  meas.slices = run.slices;
  return meas;
}

// f_r of `m` at a sample's own recorded angles.
inline Rgb Truth(const Material& m, const Sample& s) {
  return m.Evaluate(SphericalDirectionDeg(s.theta_in_deg, s.phi_in_deg),
                    SphericalDirectionDeg(s.theta_out_deg, s.phi_out_deg));
}

}  // namespace brdf::device::testing
