#!/usr/bin/python3
"""The Debian package, as a lab gets it: `cpack -G DEB` in the (already built) build folder
makes brdf-toolchain_<version>_<arch>.deb; unpacked with `dpkg-deb -x` into a temporary root
(nothing under /usr is touched) its tools, modules, material library, Python module, man pages
and bash completions work from there, and lintian reports no error.

Expected values come from outside the package: the GGX row of docs/design.md §9 evaluated in
numpy on the packaged material file, the project version from CMake, the shared libraries the
packaged ELF files need (readelf) and the Debian packages that hold them (dpkg -S) and dpkg's
version comparison against the installed packages, bash itself running the completion, man-db rendering the pages. A missing tool fails the test.

Usage: debian_package_test.py BUILD_DIR VERSION
"""
import gzip
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

BUILD, VERSION = sys.argv[1], sys.argv[2]
# Lintian warnings the package is known to carry, each explained in docs/packaging.md.
KNOWN_WARNINGS = {"maintscript-calls-ldconfig"}
failures = []
phase_started = time.monotonic()


def phase(name):
    """Prints how long the step before took (the test's time budget is about a minute)."""
    global phase_started
    now = time.monotonic()
    print("  %-28s %5.1f s" % (name, now - phase_started))
    phase_started = now


def fail(message):
    failures.append(message)
    print("FAIL: " + message, file=sys.stderr)


def run(args, check=True, **kw):
    p = subprocess.run(args, capture_output=True, text=True, timeout=240, **kw)
    if check and p.returncode != 0:
        sys.exit("FAIL: %s exited %d:\n%s%s" % (" ".join(map(str, args)), p.returncode, p.stdout,
                                                  p.stderr))
    return p


for tool in ("cpack", "dpkg-deb", "dpkg", "dpkg-query", "lintian", "man", "readelf", "bash", "ldconfig"):
    if shutil.which(tool) is None:
        sys.exit("FAIL: %s not found (tools/install-deps.sh installs it)" % tool)

work = tempfile.mkdtemp(prefix="brdf-deb-")
try:
    # --- build the package from the build tree (cpack installs, it does not build) ----------
    started = time.monotonic()
    run(["cpack", "--config", os.path.join(BUILD, "CPackConfig.cmake"), "-G", "DEB",
         "-B", os.path.join(work, "out")])
    cpack_seconds = time.monotonic() - started
    arch = run(["dpkg", "--print-architecture"]).stdout.strip()
    deb = os.path.join(work, "out", "brdf-toolchain_%s_%s.deb" % (VERSION, arch))
    if not os.path.isfile(deb):
        sys.exit("FAIL: cpack did not write %s (%s)" % (deb, os.listdir(os.path.join(work, "out"))))
    print("package %s: %d bytes, cpack %.1f s" % (os.path.basename(deb), os.path.getsize(deb),
                                                 cpack_seconds))

    def field(name):
        return run(["dpkg-deb", "-f", deb, name]).stdout.strip()

    if field("Package") != "brdf-toolchain" or field("Version") != VERSION:
        fail("control: Package %r Version %r" % (field("Package"), field("Version")))
    if field("Architecture") != arch:
        fail("control: Architecture %r, expected %r" % (field("Architecture"), arch))

    root = os.path.join(work, "root")
    run(["dpkg-deb", "-x", deb, root])
    usr = os.path.join(root, "usr")
    pydir = os.path.join(usr, "lib", "python3", "dist-packages")
    materials = os.path.join(usr, "share", "brdf-toolchain", "materials")
    module = os.path.join(usr, "lib", "brdf-toolchain", "libbrdf_oiio_reader.so")
    expected_files = [
        "bin/brdf", "bin/brdf-view", "lib/brdf-toolchain/libbrdf_oiio_reader.so",
        "share/brdf-toolchain/materials/gold.json",
        "lib/udev/rules.d/70-brdf-scatterometer.rules",
        "lib/python3/dist-packages/brdf/__init__.py",
        "share/man/man1/brdf.1.gz", "share/man/man1/brdf-view.1.gz",
        "share/bash-completion/completions/brdf", "share/bash-completion/completions/brdf-view",
        "share/doc/brdf-toolchain/copyright", "share/doc/brdf-toolchain/changelog.gz",
    ]
    for f in expected_files:
        if not os.path.isfile(os.path.join(usr, f)):
            fail("the package has no /usr/" + f)
    if not [f for f in os.listdir(os.path.join(pydir, "brdf")) if f.startswith("_brdf.") and f.endswith(".so")]:
        fail("the package has no compiled Python extension in /usr/lib/python3/dist-packages/brdf")
    for top in os.listdir(root):
        if top != "usr":
            fail("the package installs outside /usr: /" + top)
    with gzip.open(os.path.join(usr, "share/doc/brdf-toolchain/changelog.gz"), "rt") as f:
        first = f.readline()
    if not first.startswith("brdf-toolchain (%s) " % VERSION):
        fail("changelog's newest entry %r is not version %s" % (first.strip(), VERSION))

    # --- Depends: every shared library a packaged ELF file needs is named by its package -----
    depends = field("Depends")
    dep_names = {re.sub(r"\s*\(.*", "", alt).strip() for d in depends.split(",") for alt in d.split("|")}
    for must in ("python3", "python3-numpy", "libc6", "libstdc++6"):
        if must not in dep_names:
            fail("Depends lacks %s: %s" % (must, depends))
    sonames = {}
    for line in run(["ldconfig", "-p"]).stdout.splitlines()[1:]:
        m = re.match(r"\s*(\S+) \((libc6,x86-64)[^)]*\) => (\S+)", line)
        if m:
            sonames.setdefault(m.group(1), m.group(3))
    elves = []
    for dirpath, _, files in os.walk(usr):
        for f in files:
            path = os.path.join(dirpath, f)
            with open(path, "rb") as fh:
                if fh.read(4) == b"\x7fELF":
                    elves.append(path)
    if len(elves) != 5:
        fail("expected 5 ELF files (brdf, brdf-view, the image-reader module, the Python "
             "extension and its tools extension), found %s" % elves)
    needed = {}  # soname -> the packaged files that need it
    for elf in elves:
        for so in re.findall(r"\(NEEDED\)\s+Shared library: \[([^]]+)\]",
                             run(["readelf", "-d", elf]).stdout):
            needed.setdefault(so, []).append(os.path.relpath(elf, root))
    # dpkg knows a file by the name its package ships it under: /lib or /usr/lib (merged /usr),
    # the soname link or the file it points to. One dpkg -S call for all of them.
    candidates = {}
    for so in needed:
        path = sonames.get(so)
        names = [path, os.path.realpath(path)] if path else []
        names += [re.sub(r"^/usr/lib/", "/lib/", c) for c in names]
        names += [re.sub(r"^/lib/", "/usr/lib/", c) for c in names]
        candidates[so] = set(names)
    owners = {}
    all_paths = sorted(set().union(*candidates.values()))
    for line in run(["dpkg", "-S"] + all_paths, check=False).stdout.splitlines():
        m = re.match(r"([^:,\s]+)(?::\S+)?: (\S+)$", line)
        if m:
            owners[m.group(2)] = m.group(1)
    for so, users in sorted(needed.items()):
        if so in dep_names:  # a virtual name (liblapack.so.3 through alternatives)
            continue
        packages = {owners[c] for c in candidates[so] if c in owners}
        if not packages:
            fail("%s need %s, which no installed Debian package provides" % (users, so))
        elif not packages & dep_names:
            fail("%s need %s (package %s), not in Depends: %s" % (users, so, sorted(packages), depends))

    phase("cpack, control, files, Depends")
    # Every Depends clause is met by the Debian packages installed here (dpkg's own version
    # comparison), the same packages the build linked against.
    installed, provided = {}, set()
    for line in run(["dpkg-query", "-W", "-f", "${db:Status-Abbrev}\t${Package}\t${Version}\t${Provides}\n"]).stdout.splitlines():
        status, name, pkg_version, provides = (line.split("\t") + [""] * 4)[:4]
        if status.startswith("ii"):
            installed[name] = pkg_version
            provided.update(re.sub(r"\s*\(.*?\)", "", x).strip() for x in provides.split(",") if x.strip())
    for clause in depends.split(","):
        met = False
        for alt in clause.split("|"):
            m = re.fullmatch(r"\s*([^\s(]+)\s*(?:\((<<|<=|=|>=|>>)\s*([^)]+)\))?\s*", alt)
            if not m:
                fail("Depends: cannot read %r" % alt)
                continue
            name, op, wanted = m.groups()
            if name in installed:
                if op is None or run(["dpkg", "--compare-versions", installed[name],
                                      {"<<": "lt", "<=": "le", "=": "eq", ">=": "ge", ">>": "gt"}[op],
                                      wanted], check=False).returncode == 0:
                    met = True
            elif op is None and name in provided:
                met = True
        if not met:
            fail("Depends clause %r is not met by the installed packages" % clause.strip())
    phase("Depends met")
    # --- the unpacked tools ------------------------------------------------------------------
    env = {k: v for k, v in os.environ.items()
           if k not in ("BRDF_MATERIALS_DIR", "BRDF_MODULE_DIR", "PYTHONPATH")}
    brdf = os.path.join(usr, "bin", "brdf")
    version = run([brdf, "--version"], env=env).stdout.strip()
    if version != "brdf-toolchain " + VERSION:
        fail("brdf --version says %r, expected 'brdf-toolchain %s'" % (version, VERSION))

    # brdf eval of the packaged gold against docs/design.md §9's GGX row, in numpy.
    with open(os.path.join(materials, "gold.json")) as f:
        gold = json.load(f)
    assert gold["model"] == "ggx"

    def direction(theta, phi):
        t, p = np.radians(theta), np.radians(phi)
        return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])

    def ggx(l, v):
        kd = np.broadcast_to(np.asarray(gold["kd"], float), (3,))
        f0 = np.asarray(gold["f0"], float)
        a = gold["alpha"]
        h = (l + v) / np.linalg.norm(l + v)
        tan2 = lambda x: (1 - x[2] ** 2) / x[2] ** 2
        d = a * a / (np.pi * h[2] ** 4 * (a * a + tan2(h)) ** 2)
        g1 = lambda x: 2 / (1 + np.sqrt(1 + a * a * tan2(x)))
        fresnel = f0 + (1 - f0) * (1 - v @ h) ** 5
        return kd / np.pi + fresnel * g1(l) * g1(v) * d / (4 * l[2] * v[2])

    pairs = [((30, 0), (30, 180)), ((0, 0), (45, 90)), ((60, 0), (20, 200)), ((40, 10), (35, 185))]
    cli_values = []
    for (ti, pi), (to, po) in pairs:
        out = run([brdf, "eval", "gold", "--in", "%g,%g" % (ti, pi), "--out", "%g,%g" % (to, po)],
                  env=env, cwd=work).stdout.split()
        got = np.array([float(x) for x in out])
        cli_values.append(got)
        want = ggx(direction(ti, pi), direction(to, po))
        # brdf eval prints 9 significant digits: at most 5e-9 relative rounding.
        if not np.allclose(got, want, rtol=1e-8, atol=0):
            fail("brdf eval gold --in %g,%g --out %g,%g = %s, GGX of gold.json = %s"
                 % (ti, pi, to, po, got, want))

    # The library is the packaged one (a broken packaged gold.json is what eval reads) ...
    listing = json.loads(run([brdf, "materials", "--json"], env=env, cwd=work).stdout)
    files = [m["file"] for m in (listing["materials"] if isinstance(listing, dict) else listing)]
    if not files or not all(os.path.dirname(f) == materials for f in files):
        fail("brdf materials lists files outside %s: %s" % (materials, files[:3]))
    saved = open(os.path.join(materials, "gold.json"), "rb").read()
    with open(os.path.join(materials, "gold.json"), "w") as f:
        f.write('{"model": ')
    p = run([brdf, "eval", "gold", "--in", "30,0", "--out", "30,180"], check=False, env=env, cwd=work)
    if p.returncode == 0 or os.path.join(materials, "gold.json") not in p.stderr:
        fail("a broken packaged gold.json: exit %d, stderr %r (must name it)" % (p.returncode, p.stderr))
    with open(os.path.join(materials, "gold.json"), "wb") as f:
        f.write(saved)

    # ... and so is the image-reader module: an environment map read through OpenImageIO.
    import OpenImageIO as oiio
    env_map = os.path.join(work, "env.hdr")
    out = oiio.ImageOutput.create(env_map)
    out.open(env_map, oiio.ImageSpec(16, 8, 3, "float"))
    out.write_image(np.full((8, 16, 3), 0.5, np.float32))
    out.close()
    preview = [brdf, "preview", "gold", "--env", env_map, "--size", "8", "--quiet",
               "--out", os.path.join(work, "p.png")]
    run(preview, env=env, cwd=work)
    saved = open(module, "rb").read()
    with open(module, "wb") as f:
        f.write(b"not a module")
    p = run(preview + ["--force"], check=False, env=env, cwd=work)
    if p.returncode == 0 or module not in p.stderr:
        fail("a damaged packaged module: exit %d, stderr %r (must name %s)" % (p.returncode, p.stderr, module))
    with open(module, "wb") as f:
        f.write(saved)

    view = run([os.path.join(usr, "bin", "brdf-view"), "--help"], env=env)
    if not view.stdout.startswith("brdf-view: "):
        fail("brdf-view --help: %r" % view.stdout[:80])
    view_version = run([os.path.join(usr, "bin", "brdf-view"), "--version"], env=env).stdout.strip()
    if view_version != "brdf-toolchain " + VERSION:
        fail("brdf-view --version says %r" % view_version)

    phase("unpacked tools")
    # --- the Python module, with Debian's interpreter --------------------------------------------
    script = ("import brdf, os, sys\n"
              "print(brdf.__file__)\n"
              "print(os.environ['BRDF_MATERIALS_DIR'])\n"
              "print(os.environ['BRDF_MODULE_DIR'])\n"
              "g = brdf.open('gold')\n"
              "for (ti, pi), (to, po) in %r:\n"
              "    print(' '.join('%%.9g' %% x for x in g.eval_deg(ti, pi, to, po)))\n" % (pairs,))
    p = run(["/usr/bin/python3", "-c", script], env=dict(env, PYTHONPATH=pydir), cwd=work)
    lines = p.stdout.splitlines()
    if not lines[0].startswith(os.path.join(pydir, "brdf") + os.sep):
        fail("import brdf found %s, not the unpacked package" % lines[0])
    if lines[1] != materials or lines[2] != os.path.dirname(module):
        fail("the unpacked Python module looks for materials in %s and modules in %s" % (lines[1], lines[2]))
    for got, want in zip(lines[3:], cli_values):
        if not np.array_equal(np.array([float(x) for x in got.split()]), want):
            fail("Python eval_deg of gold %s differs from brdf eval %s" % (got, want))

    phase("python")
    # --- man pages: render without warnings, and hold every command and option ------------------
    def help_entries(text):
        """Subcommands and option names of one --help text (an independent reading)."""
        subs, opts, choices, section = [], [], {}, None
        for line in text.splitlines():
            if re.fullmatch(r"[A-Z][A-Za-z ]*:", line):
                section = line[:-1]
            elif section and re.match(r"  \S", line):
                spec = re.split(r"\s{2,}", line.strip())[0]
                if section == "Subcommands":
                    subs.append(spec)
                elif section != "Positionals":
                    names = spec.split(" ")[0].split(",")
                    opts.extend(names)
                    m = re.search(r"\{(.*?)\}", spec)
                    if m:
                        for n in names:
                            choices[n] = m.group(1).split(",")
        return subs, opts, choices

    top = help_entries(run([brdf, "--help"], env=env).stdout)
    subhelp = {s: help_entries(run([brdf, s, "--help"], env=env).stdout) for s in top[0]}
    if len(top[0]) < 10:
        fail("brdf --help lists only %s" % top[0])
    viewhelp = help_entries(view.stdout)

    def render(page):
        """The page as man shows it: without a warning on an 80-column terminal; returned
        250 columns wide (each entry on one line, for the searches below)."""
        for width in ("80", "250"):
            p = run(["man", "--warnings", "-E", "UTF-8", "-l", page], check=False,
                    env=dict(env, MANWIDTH=width, LC_ALL="C.UTF-8", MAN_KEEP_FORMATTING=""))
            if p.returncode != 0 or p.stderr.strip():
                fail("man -l %s at %s columns: exit %d, %s" % (page, width, p.returncode, p.stderr.strip()))
        return re.sub(r".\x08", "", p.stdout)

    page = render(os.path.join(usr, "share/man/man1/brdf.1.gz"))
    words = set(re.findall(r"[-\w]+", page.replace("\u2010", "-")))
    for sub in top[0]:
        if not re.search(r"^ {3}brdf %s$" % re.escape(sub), page, re.M):
            fail("brdf(1) has no section 'brdf %s'" % sub)
        for opt in subhelp[sub][1]:
            if opt not in words:
                fail("brdf(1) does not mention %s of brdf %s" % (opt, sub))
    view_page = render(os.path.join(usr, "share/man/man1/brdf-view.1.gz"))
    view_words = set(re.findall(r"[-\w]+", view_page))
    for opt in viewhelp[1]:
        if opt not in view_words:
            fail("brdf-view(1) does not mention %s" % opt)

    phase("man pages")
    # --- bash completion: what bash offers is exactly what --help lists --------------------------
    def complete(program, words):
        comp = os.path.join(usr, "share/bash-completion/completions", program)
        script = ('source "$0"; COMP_WORDS=(%s); COMP_CWORD=%d; _%s; printf "%%s\\n" "${COMPREPLY[@]}"'
                  % (" ".join("'%s'" % w for w in words), len(words) - 1, program.replace("-", "_")))
        out = run(["bash", "--norc", "-c", script, comp], env=env).stdout
        return sorted(x for x in out.splitlines() if x)

    if complete("brdf", ["brdf", ""]) != sorted(top[0]):
        fail("completion of 'brdf ' offers %s, --help lists %s" % (complete("brdf", ["brdf", ""]), top[0]))
    if complete("brdf", ["brdf", "-"]) != sorted(top[1]):
        fail("completion of 'brdf -' offers %s, --help lists %s" % (complete("brdf", ["brdf", "-"]), top[1]))
    for sub, (_, opts, choices) in subhelp.items():
        offered = complete("brdf", ["brdf", sub, "-"])
        if offered != sorted(opts):
            fail("completion of 'brdf %s -' offers %s, its --help lists %s" % (sub, offered, sorted(opts)))
        for opt, values in choices.items():
            offered = complete("brdf", ["brdf", sub, opt, ""])
            if offered != sorted(values):
                fail("completion of 'brdf %s %s ' offers %s, --help lists %s" % (sub, opt, offered, values))
    offered = complete("brdf-view", ["brdf-view", "-"])
    if offered != sorted(viewhelp[1]):
        fail("completion of 'brdf-view -' offers %s, --help lists %s" % (offered, sorted(viewhelp[1])))
    for opt, values in viewhelp[2].items():
        offered = complete("brdf-view", ["brdf-view", opt, ""])
        if offered != sorted(values):
            fail("completion of 'brdf-view %s ' offers %s, --help lists %s" % (opt, offered, values))

    phase("bash completion")
    # --- lintian: no error; warnings only the documented ones -------------------------------
    started = time.monotonic()
    p = run(["lintian", "--fail-on", "error", deb], check=False)
    lintian_seconds = time.monotonic() - started
    phase("lintian")
    tags = re.findall(r"^([EW]): brdf-toolchain: (\S+)", p.stdout, re.M)
    errors = [t for kind, t in tags if kind == "E"]
    if p.returncode != 0 or errors:
        fail("lintian: exit %d, errors %s\n%s" % (p.returncode, errors, p.stdout))
    unexplained = {t for kind, t in tags if kind == "W"} - KNOWN_WARNINGS
    if unexplained:
        fail("lintian warnings not explained in docs/packaging.md: %s" % sorted(unexplained))
    print("lintian %.1f s: %d tag(s) %s" % (lintian_seconds, len(tags), sorted({t for _, t in tags})))
finally:
    shutil.rmtree(work, ignore_errors=True)

if failures:
    sys.exit("%d failure(s)" % len(failures))
print("ok")
