#!/usr/bin/python3
"""Commands that need no image reader must not map the heavy libraries, and stay small.

The libraries a process really maps come from the dynamic loader itself: with LD_DEBUG=libs it
prints "calling init: <path>" for every shared object it initialises, including those opened
later with dlopen. A command fails this test when any of them is OpenImageIO or VTK (or the
libraries only they bring: OpenVDB, GDAL). Ceres is linked directly: measured, it adds about
11 ms and 3 MiB to a start (docs/benchmarks.md, "Start-up cost"), inside the budget. The detector is checked on a positive
control: a program that reads an image through brdf::image_io must show OpenImageIO.

Peak RSS (GNU time's %M, the child's ru_maxrss) of each non-image command must stay
under 30 MiB (the start-up target is "under 50 ms and 30 MB"; time is measured by bench/startup.sh, since a
timing assertion on a shared machine would fail for reasons that are not the program's).
`info` of a capture is not a start-up-only command: it builds the capture's LUT with the
default blind-spot fill for its leave-last-slice-out figure and physical sanity report
(docs/design.md §5), which holds about 100 MB of slices, views and model values; it keeps
the library check and a working-memory budget of 160 MiB, and the start-up budget is checked
on `info` of a material file.

usage: startup_libraries.py BRDF IMAGE_PROBE SAMPLES_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

FORBIDDEN = re.compile(r"lib(OpenImageIO|vtk|openvdb|gdal)[^/\s]*\.so")
MAX_RSS_KIB = 30 * 1024
MAX_FILL_RSS_KIB = 160 * 1024  # `info` of a capture: the blind-spot fill and sanity report


def loaded_libraries(argv, workdir, tag):
    """Runs argv under LD_DEBUG=libs and returns the paths the loader initialised."""
    log_base = os.path.join(workdir, "ld." + tag)
    env = dict(os.environ, LD_DEBUG="libs", LD_DEBUG_OUTPUT=log_base)
    run = subprocess.run(argv, env=env, cwd=workdir, capture_output=True, text=True, timeout=120)
    if run.returncode != 0:
        sys.exit(f"FAIL: {' '.join(argv)} exited {run.returncode}: {run.stderr.strip()}")
    libraries = []
    for name in os.listdir(workdir):
        if name.startswith("ld." + tag + "."):
            with open(os.path.join(workdir, name), encoding="utf-8", errors="replace") as log:
                for line in log:
                    match = re.search(r"calling init: (\S+)", line)
                    if match:
                        libraries.append(match.group(1))
    if not libraries:
        sys.exit(f"FAIL: LD_DEBUG=libs reported no library for {' '.join(argv)}: "
                 "the detector itself is broken")
    return libraries


def peak_rss_kib(argv, workdir):
    """Peak RSS of argv in KiB, from GNU time (%M). Measuring it with wait4 from here would
    count the forked Python interpreter's pages before exec, about 5 MiB."""
    report = os.path.join(workdir, "time.txt")
    run = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", report, *argv], cwd=workdir,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         timeout=120)
    if run.returncode != 0:
        sys.exit(f"FAIL: {' '.join(argv)} exited {run.returncode}: {run.stderr.strip()}")
    with open(report, encoding="utf-8") as text:
        return int(text.read().split()[-1])


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    brdf, probe, samples = (os.path.abspath(a) for a in sys.argv[1:])
    workdir = tempfile.mkdtemp(prefix="brdf_startup_test_")
    failures = []
    try:
        gold = os.path.join(samples, "captures", "gold.bpc")
        material = os.path.join(samples, "materials", "aluminium.json")
        for path in (gold, material):
            if not os.path.isfile(path):
                sys.exit(f"FAIL: sample file {path} is missing")
        non_image = {
            "version": [brdf, "--version"],
            "materials": [brdf, "materials"],
            "info": [brdf, "info", material],
            "info_capture": [brdf, "info", gold],
            "eval": [brdf, "eval", material, "--in", "40,0", "--out", "40,180"],
            # A small geometry: the point is what the process maps, not the capture's length.
            "capture": [brdf, "capture", "--device", "sim", "--material", "gold", "--sample",
                        "startup test", "--theta-in", "0", "--phi-out-step", "30",
                        "--theta-out-step", "15", "--out", "capture.bpc", "--force"],
        }
        # Writing EXR and PNG goes through OpenEXR and libpng, so convert stays light too.
        writes_images = {
            "convert": [brdf, "convert", material, "--out", "luts", "--formats",
                        "exr,png,json,ktx2"],
        }
        for tag, argv in {**non_image, **writes_images}.items():
            heavy = sorted({lib for lib in loaded_libraries(argv, workdir, tag)
                            if FORBIDDEN.search(lib)})
            if heavy:
                failures.append(f"'brdf {' '.join(argv[1:])}' maps {', '.join(heavy)}")
        for tag, argv in non_image.items():
            rss = peak_rss_kib(argv, workdir)
            print(f"{tag}: peak RSS {rss} KiB")
            budget = MAX_FILL_RSS_KIB if tag == "info_capture" else MAX_RSS_KIB
            if rss >= budget:
                failures.append(f"'brdf {' '.join(argv[1:])}' peaks at {rss} KiB, "
                                f"budget {budget} KiB")
        # The executable itself must not even list them (ldd resolves DT_NEEDED recursively).
        ldd = subprocess.run(["ldd", brdf], capture_output=True, text=True, check=True).stdout
        listed = sorted({m.group(0) for m in FORBIDDEN.finditer(ldd)})
        if listed:
            failures.append(f"ldd {brdf} lists {', '.join(listed)}")
        # Positive control: reading an image loads the OpenImageIO module, and the detector
        # sees it.
        probe_libs = loaded_libraries([probe, os.path.join(workdir, "probe.exr")], workdir,
                                      "probe")
        if not any("libOpenImageIO" in lib for lib in probe_libs):
            failures.append("positive control: the image-reading probe did not show "
                            "libOpenImageIO in LD_DEBUG=libs, so the detector proves nothing")
        if not any("libbrdf_oiio_reader.so" in lib for lib in probe_libs):
            failures.append("positive control: libbrdf_oiio_reader.so was not loaded")
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    if failures:
        for failure in failures:
            print("FAIL:", failure)
        sys.exit(1)
    print("OK: no command that needs no image reader maps OpenImageIO, VTK or Ceres")


if __name__ == "__main__":
    main()
