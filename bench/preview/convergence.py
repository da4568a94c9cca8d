#!/usr/bin/python3
"""Time for `brdf preview` to reach 1 % RMS of a converged reference (docs/benchmarks.md).

  convergence.py BRDF_TOOL OUT_DIR SOURCE... [--size-ref 128] [--ref-spp 2048] [--jobs 2]

For each source, under the default `studio` map (1024 × 512):
 1. the error curve: renders of SIZE_REF² pixels at 4, 16, 64 and 256 passes (seed 1) against
    a reference of REF_SPP passes (seed 2); the error is the RMS over object pixels relative to
    the reference's mean there (preview.h CompareImages). A pixel's estimator depends on its
    normal and view only, not on the image size, so the curve holds at 512² too.
 2. a power law e(N) = c·N^−k fitted to the four points, with the reference's own error
    e(REF_SPP) removed in quadrature; N₁ = the passes where e(N) = 1 %.
 3. the time: `brdf preview --size 512 --spp N₁ --jobs JOBS` timed end to end (opening the
    source, building the samplers, rendering and writing the EXR), median of 3 runs; when
    N₁ > 128 the set-up plus N₁ passes at the rate measured between 8- and 40-pass runs.
Prints one Markdown table row per source.
"""
import math
import os
import subprocess
import sys
import time

import numpy as np
import OpenImageIO as oiio


def read(path):
    image = oiio.ImageInput.open(path)
    pixels = np.asarray(image.read_image(0, 0, 0, 3, oiio.FLOAT), float)
    image.close()
    return pixels


def relative_rms(a, ref):
    mask = ref.sum(axis=2) > 0  # --no-background: the object's pixels
    d = (a - ref)[mask]
    return math.sqrt((d ** 2).mean()) / ref[mask].mean()


def render(tool, source, out, size, spp, seed, jobs):
    start = time.perf_counter()
    subprocess.run([tool, "preview", source, "--size", str(size), "--spp", str(spp), "--seed",
                    str(seed), "--jobs", str(jobs), "--no-background", "--quiet", "--out", out],
                   check=True)
    return time.perf_counter() - start


def main(argv):
    tool, out_dir, sources = argv[0], argv[1], []
    size_ref, ref_spp, jobs = 128, 2048, 2
    i = 2
    while i < len(argv):
        if argv[i] == "--size-ref":
            size_ref = int(argv[i + 1]); i += 2
        elif argv[i] == "--ref-spp":
            ref_spp = int(argv[i + 1]); i += 2
        elif argv[i] == "--jobs":
            jobs = int(argv[i + 1]); i += 2
        else:
            sources.append(argv[i]); i += 1
    os.makedirs(out_dir, exist_ok=True)
    print("| source | e(4) | e(16) | e(64) | e(256) | k | passes to 1 % | time to 1 % at 512² (s) | s per pass at 512² |")
    print("|---|---|---|---|---|---|---|---|---|")
    for source in sources:
        name = os.path.basename(source)
        ref_path = os.path.join(out_dir, name + ".ref.exr")
        render(tool, source, ref_path, size_ref, ref_spp, 2, jobs)
        ref = read(ref_path)
        counts, errors = [4, 16, 64, 256], []
        for n in counts:
            path = os.path.join(out_dir, "%s.%d.exr" % (name, n))
            render(tool, source, path, size_ref, n, 1, jobs)
            errors.append(relative_rms(read(path), ref))
        slope, intercept = np.polyfit(np.log(counts), np.log(errors), 1)
        k, c = -slope, math.exp(intercept)
        e_ref = c * ref_spp ** -k
        # Measured² = true² + reference², so the true curve reaches 1 % where
        # c·N^−k = √(0.01² + e_ref²) in the measured fit.
        target = math.sqrt(0.01 ** 2 + e_ref ** 2)
        n1 = max(1, int(math.ceil((c / target) ** (1.0 / k))))
        # Time per pass at 512² from two short runs (their difference excludes the set-up).
        t8 = render(tool, source, os.path.join(out_dir, name + ".p8.exr"), 512, 8, 1, jobs)
        t40 = render(tool, source, os.path.join(out_dir, name + ".p40.exr"), 512, 40, 1, jobs)
        per_pass = (t40 - t8) / 32.0
        if n1 <= 128:
            times = sorted(render(tool, source, os.path.join(out_dir, name + ".512.exr"), 512,
                                  n1, 1, jobs) for _ in range(3))
            total = "%.1f" % times[1]
        else:  # too long to run here: set-up plus passes at the measured rate
            total = "≈ %.0f (estimated)" % (t8 - 8 * per_pass + n1 * per_pass)
        print("| %s | %.3f | %.3f | %.3f | %.3f | %.2f | %d | %s | %.3f |" % (
            name, errors[0], errors[1], errors[2], errors[3], k, n1, total, per_pass))
        sys.stdout.flush()


if __name__ == "__main__":
    main(sys.argv[1:])
