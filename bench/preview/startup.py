#!/usr/bin/python3
"""Two builds of `brdf preview` side by side: the fixed cost of a preview (the map, its hierarchy,
opening the source) and whether the image changed (docs/benchmarks.md,
"Environment-lit preview").

  startup.py BEFORE_TOOL AFTER_TOOL OUT_DIR SOURCE... [--runs 5] [--jobs 2]

1. Start-up: `--size 8` previews (64 pixels, so nearly all of the time is the fixed cost) of the
   first SOURCE under each map, studio (the default), sky, furnace, axes and a 1024 × 512 .exr
   written here; interleaved rounds, medians of wall clock and CPU (user + system).
2. Identity: the default 512² preview of every SOURCE by both builds; the largest relative
   difference of any pixel channel (|after − before| / |before| over the object's non-zero
   values) and the BRDF evaluations each build reports.
"""
import os
import statistics
import sys

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from convergence import read  # noqa: E402
from fast_path import SIZE, parse, run  # noqa: E402
from before_after import counts  # noqa: E402


def write_exr_map(path):
    """A smooth 1024 × 512 equirectangular map with a bright spot (any content does: the cost of
    reading and building its hierarchy does not depend on the values)."""
    h, w = 512, 1024
    theta = (np.arange(h)[:, None] + 0.5) / h * np.pi
    phi = (np.arange(w)[None, :] + 0.5) / w * 2 * np.pi
    base = 0.2 + 0.1 * np.cos(theta) + 0.05 * np.sin(3 * phi)
    spot = 20.0 * np.exp(-((theta - 0.7) ** 2 + (phi - 1.0) ** 2) / 0.01)
    rgb = np.stack([base + spot, base * 0.9 + spot, base * 0.8 + spot], axis=2).astype(np.float32)
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(w, h, 3, oiio.FLOAT))
    out.write_image(rgb)
    out.close()


def main(argv):
    positional, runs, _, jobs, _ = parse(argv)
    tools, out_dir, sources = positional[0:2], positional[2], positional[3:]
    os.makedirs(out_dir, exist_ok=True)
    exr_map = os.path.join(out_dir, "map.exr")
    write_exr_map(exr_map)
    print("load average before: %.2f %.2f %.2f" % os.getloadavg())
    print("| map (`--size 8`) | wall before | wall after | ratio | CPU before | CPU after | ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for env in ("studio", "sky", "furnace", "axes", exr_map):
        rows = [[], []]
        for _ in range(runs):
            for b, tool in enumerate(tools):
                wall, cpu, _ = run([tool, "preview", sources[0], "--size", "8", "--jobs", str(jobs),
                                    "--quiet", "--no-background", "--force", "--env", env,
                                    "--out", os.path.join(out_dir, "s8.%d.exr" % b)])
                rows[b].append((wall, cpu))
        med = [[statistics.median(r[k] for r in rows[b]) for k in (0, 1)] for b in (0, 1)]
        print("| %s | %.3f | %.3f | %.2f× | %.3f | %.3f | %.2f× |" % (
            os.path.basename(env), med[0][0], med[1][0], med[0][0] / med[1][0], med[0][1],
            med[1][1], med[0][1] / med[1][1]))
        sys.stdout.flush()
    print()
    print("| source (512², studio) | max relative pixel difference | values that differ | "
          "BRDF evaluations before | after |")
    print("|---|---:|---:|---:|---:|")
    for source in sources:
        images, evals = [], []
        for b, tool in enumerate(tools):
            path = os.path.join(out_dir, "%s.%d.exr" % (os.path.basename(source), b))
            _, _, err = run([tool, "preview", source, "--size", str(SIZE), "--jobs", str(jobs),
                             "--no-background", "--force", "--out", path])
            images.append(read(path))
            evals.append(counts(err)[0])
        before, after = images
        diff = np.abs(after - before)
        nonzero = np.abs(before) > 0
        rel = np.max(diff[nonzero] / np.abs(before[nonzero])) if nonzero.any() else 0.0
        print("| %s | %.3g | %d of %d | %s | %s |" % (
            os.path.basename(source), rel, int((diff > 0).sum()), diff.size, evals[0], evals[1]))
        sys.stdout.flush()
    print("load average after: %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main(sys.argv[1:])
