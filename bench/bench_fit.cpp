// Fit time per model on one full capture (bench/fit/compare_scipy.sh drives it): the whole
// FitMaterial (sweep + multi-start refinement) on 1 and 2 threads, and one Ceres refinement
// from a fixed generic start, whose data and start are written out so SciPy's least_squares
// can fit the same model, loss and data from the same start side by side (every model).
//
//   bench_fit CAPTURE.bpc OUT_DIR [REPEATS [MODEL]]
// prints one JSON object per line: {"model", "mode", "threads", "seconds" (median), "cost"}.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/models.h"
#include "brdf/fit/fit.h"
#include "fit_data.h"  // private to brdf_fit: the exact samples and weights the fit uses

using namespace brdf;
using processing::FitOptions;

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void WriteData(const std::string& path, const processing::FitData& data) {
  std::ofstream out(path);
  out.precision(17);
  out << "n_dot_l,n_dot_v,n_dot_h,v_dot_h,l_dot_v,v_dot_r,m_r,m_g,m_b,cos_in,sqrt_w\n";
  for (const processing::FitSample& s : data.samples)
    out << s.g.n_dot_l << ',' << s.g.n_dot_v << ',' << s.g.n_dot_h << ',' << s.g.v_dot_h << ','
        << s.g.l_dot_v << ',' << s.g.v_dot_r << ',' << s.m[0] << ',' << s.m[1] << ',' << s.m[2]
        << ',' << s.cos_in << ',' << s.sqrt_w << '\n';
}

// Runs FitMaterial `repeats` times with `options` and prints one JSON line with the median wall
// and CPU seconds and the last run's iterations and final cost.
void TimeFits(const Measurement& meas, const FitOptions& options, int repeats,
              const std::string& name, const char* mode) {
  std::vector<double> seconds, cpu;
  double cost = 0;
  int iterations = 0;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    const processing::FitResult fit = processing::FitMaterial(meas, options);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    cost = fit.report.final_cost;
    iterations = fit.report.iterations;
  }
  std::printf(
      "{\"model\": \"%s\", \"mode\": \"%s\", \"threads\": %d, \"seconds\": %.4f, "
      "\"cpu_seconds\": %.4f, \"iterations\": %d, \"cost\": %.10g}\n",
      name.c_str(), mode, options.threads, Median(seconds), Median(cpu), iterations, cost);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_fit CAPTURE.bpc OUT_DIR [REPEATS [MODEL]]\n");
    return 2;
  }
  const Measurement meas = ReadBpc(argv[1]).measurement;
  const std::string out_dir = argv[2];
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
  WriteData(out_dir + "/fit_data.csv", processing::PrepareFitData(meas, FitOptions{}));
  std::fprintf(stderr, "%zu samples\n", meas.SampleCount());

  const Model models[] = {Model::kGgx,
                          Model::kLafortune,
                          Model::kBlinnPhong,
                          Model::kWard,
                          Model::kUnrealDefaultLit,
                          Model::kUnityHdrpLit,
                          Model::kUnityHdrpLitSpecular,
                          Model::kUnityUrpLit,
                          Model::kUnityUrpLitSpecular};
  for (Model model : models) {
    const std::string name(ModelName(model));
    if (argc > 4 && name != argv[4]) continue;
    for (int threads : {1, 2}) {
      FitOptions o;
      o.model = model;
      o.threads = threads;
      TimeFits(meas, o, repeats, name, "multistart");
    }
    {
      // One refinement from the models' generic start (ParameterInfo::start), on one thread.
      Material start;
      start.model = model;
      for (const ParameterInfo& p : DescribeModel(model).parameters)
        for (int c = 0; c < p.Count(); ++c)
          start.values[static_cast<std::size_t>(p.offset + c)] = p.start;
      std::ofstream(out_dir + "/start_" + name + ".json") << MaterialToJson(start);
      FitOptions o;
      o.model = model;
      o.start = start;
      o.starts = 1;
      TimeFits(meas, o, repeats, name, "single-start");
      // What every fit pays besides the solver: the data preparation, one cost and the error
      // report (EvaluateFit runs exactly those), at the generic start.
      std::vector<double> seconds, cpu;
      for (int r = 0; r < repeats; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        const processing::FitReport report = processing::EvaluateFit(meas, start, o);
        seconds.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
        if (!(report.final_cost > 0)) std::fprintf(stderr, "evaluate: no cost\n");
      }
      // Its parts: the data preparation alone and the error report alone.
      std::vector<double> prepare_cpu, report_cpu;
      for (int r = 0; r < repeats; ++r) {
        std::clock_t c0 = std::clock();
        const processing::FitData data = processing::PrepareFitData(meas, o);
        prepare_cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
        processing::FitReport report;
        c0 = std::clock();
        processing::FillErrors(data, start, &report);
        report_cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
      }
      std::printf(
          "{\"model\": \"%s\", \"mode\": \"fixed-overhead\", \"threads\": 1, \"seconds\": %.4f, "
          "\"cpu_seconds\": %.4f, \"prepare_cpu_seconds\": %.4f, \"report_cpu_seconds\": %.4f}\n",
          name.c_str(), Median(seconds), Median(cpu), Median(prepare_cpu), Median(report_cpu));
      std::fflush(stdout);
    }
  }
  return 0;
}
