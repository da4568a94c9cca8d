#!/usr/bin/python3
"""Time for `brdf preview` (default: the hierarchical quadrature on the sphere) to give a 512²
image within 1 % RMS of a converged reference, beside the Monte Carlo baseline (docs/benchmarks.md).

  fast_path.py BRDF_TOOL OUT_DIR SOURCE... [--runs 5] [--ref-pixels 1500] [--jobs 2]
               [--keep-reference]

For each source, under the default `studio` map (1024 × 512), sphere, 512 × 512, --no-background:
 1. the reference: the brute-force quadrature (`--estimator quadrature --subdivisions 1`: every map
    pixel, midpoint rule; independent of the hierarchy, the interpolation and their tolerances) at
    REF_PIXELS image pixels chosen at random (`--sample-pixels`, a fixed choice), computed once
    (reused with --keep-reference when the file exists);
 2. RUNS interleaved rounds of: the default render (`brdf preview SRC`), and the Monte Carlo
    baseline at 4 and 20 passes (`--estimator mis --spp 4|20`); wall clock and CPU time
    (user + system of the child) of each whole process (opening the source, the map, the render,
    writing the EXR);
 3. the error of an image: RMS over the reference's pixels of (image − reference), all channels,
    relative to the reference's mean there;
 4. the baseline's time to 1 %: the 20-pass error extrapolated with e ∝ N^−0.72 (the exponent
    bench/preview/convergence.py measured for these sources) to the passes N₁ where it is 1 %,
    times the per-pass cost (t(20) − t(4))/16, plus the set-up t(4) − 4·per-pass.
Prints the load average before and after and one Markdown row per source (medians over RUNS).
"""
import math
import os
import resource
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from convergence import read, relative_rms  # noqa: E402  (the same error definition)

SIZE = 512
MC_EXPONENT = 0.72


def run(args):
    """Runs the tool; returns (wall seconds, CPU seconds, stderr)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(args, check=True, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, done.stderr


def parse(argv):
    """(positional arguments, runs, ref_pixels, jobs, keep) from the command line."""
    positional = []
    runs, ref_pixels, jobs, keep = 5, 1500, 2, False
    i = 0
    while i < len(argv):
        if argv[i] == "--runs":
            runs = int(argv[i + 1]); i += 2
        elif argv[i] == "--ref-pixels":
            ref_pixels = int(argv[i + 1]); i += 2
        elif argv[i] == "--jobs":
            jobs = int(argv[i + 1]); i += 2
        elif argv[i] == "--keep-reference":
            keep = True; i += 1
        else:
            positional.append(argv[i]); i += 1
    return positional, runs, ref_pixels, jobs, keep


def main(argv):
    positional, runs, ref_pixels, jobs, keep = parse(argv)
    tool, out_dir, sources = positional[0], positional[1], positional[2:]
    os.makedirs(out_dir, exist_ok=True)
    common = ["--size", str(SIZE), "--jobs", str(jobs), "--no-background", "--force"]
    print("load average before: %.1f %.1f %.1f" % os.getloadavg())
    rows = []
    for source in sources:
        name = os.path.basename(source)
        ref_path = os.path.join(out_dir, name + ".reference.exr")
        if not (keep and os.path.exists(ref_path)):
            run([tool, "preview", source, "--estimator", "quadrature", "--subdivisions", "1",
                 "--sample-pixels", str(ref_pixels), "--quiet", "--out", ref_path] + common)
        ref = read(ref_path)
        fast, mc4, mc20 = [], [], []
        evaluations = ""
        for _ in range(runs):
            path = os.path.join(out_dir, name + ".fast.exr")
            wall, cpu, err = run([tool, "preview", source, "--out", path] + common)
            fast.append((wall, cpu, relative_rms(read(path), ref)))
            for line in err.splitlines():
                if "BRDF evaluations" in line:
                    evaluations = line.split(", ")[1].split(" ")[0]
            path4 = os.path.join(out_dir, name + ".mc4.exr")
            wall, cpu, _ = run([tool, "preview", source, "--estimator", "mis", "--spp", "4",
                                "--quiet", "--out", path4] + common)
            mc4.append((wall, cpu))
            path20 = os.path.join(out_dir, name + ".mc20.exr")
            wall, cpu, _ = run([tool, "preview", source, "--estimator", "mis", "--spp", "20",
                                "--quiet", "--out", path20] + common)
            mc20.append((wall, cpu, relative_rms(read(path20), ref)))
        med = lambda rows, k: statistics.median(r[k] for r in rows)
        e20 = med(mc20, 2)
        passes_to_1 = 20.0 * (e20 / 0.01) ** (1.0 / MC_EXPONENT)
        mc_time = []
        for k in (0, 1):  # wall, CPU
            per_pass = (med(mc20, k) - med(mc4, k)) / 16.0
            mc_time.append(med(mc4, k) - 4 * per_pass + passes_to_1 * per_pass)
        rows.append("| %s | **%.2f** | %.2f | %.3f %% | %s | %.1f %% | %.0f | %.0f | %.0f | %.0f× |" % (
            name, med(fast, 0), med(fast, 1), 100 * med(fast, 2), evaluations, 100 * e20,
            passes_to_1, mc_time[0], mc_time[1], mc_time[1] / med(fast, 1)))
        print(rows[-1])
        sys.stdout.flush()
    print("load average after: %.1f %.1f %.1f" % os.getloadavg())
    print()
    print("| source | default (hierarchical) wall s | CPU s | error vs reference | BRDF "
          "evaluations | MC error at 20 passes | MC passes to 1 % | MC time to 1 % wall s | "
          "CPU s | CPU ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(r)


if __name__ == "__main__":
    main(sys.argv[1:])
