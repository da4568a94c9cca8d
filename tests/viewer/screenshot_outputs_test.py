"""brdf-view --screenshot checks its outputs before any work and says why in one line, without
VTK's log lines or terminal colours: a missing folder, a name that is not .png (a .jpg name got
PNG bytes), /dev/null (it created /dev/null.json), an existing PNG without --force, and a
--size beyond the limit said as a size (it was "expected WIDTHxHEIGHT"); a file that does not
load is named once."""
import os
import subprocess
import sys
import tempfile

view = sys.argv[1]
failures = []


def run(args):
    p = subprocess.run([view] + args, capture_output=True, text=True, timeout=60)
    return p.returncode, p.stderr


def expect(label, args, code, needle):
    got_code, err = run(args)
    lines = err.splitlines()
    if got_code != code:
        failures.append(f"{label}: exit {got_code}, expected {code}: {err!r}")
    if len(lines) != 1:
        failures.append(f"{label}: expected one line, got {len(lines)}: {err!r}")
    if needle not in err:
        failures.append(f"{label}: expected {needle!r} in {err!r}")
    for bad in ("\x1b[", "vtk", "Ran out of disk space"):
        if bad in err:
            failures.append(f"{label}: {bad!r} in {err!r}")


with tempfile.TemporaryDirectory() as d:
    material = os.path.join(d, "white.json")
    with open(material, "w") as f:
        f.write('{"model": "lambert", "rho": 1.0}')
    missing = os.path.join(d, "missing")
    expect("missing folder", [material, "--screenshot", os.path.join(missing, "s.png")], 1,
           f"{missing}/s.png: cannot write into the folder {missing}: No such file or directory")
    expect("jpg", [material, "--screenshot", os.path.join(d, "s.jpg")], 1,
           "--screenshot: expected a .png file name, got '" + os.path.join(d, "s.jpg") + "'")
    if os.path.exists(os.path.join(d, "s.jpg")):
        failures.append("a .jpg was written")
    existed = os.path.exists("/dev/null.json")
    expect("/dev/null", [material, "--screenshot", "/dev/null"], 1,
           "--screenshot: expected a .png file name, got '/dev/null'")
    if not existed and os.path.exists("/dev/null.json"):
        failures.append("/dev/null.json was created")
    expect("size", [material, "--size", "100000x100000", "--screenshot", os.path.join(d, "b.png")],
           2, "the size must be 64 to 8192 pixels each way, got '100000x100000'")
    existing = os.path.join(d, "old.png")
    with open(existing, "wb") as f:
        f.write(b"not replaced")
    expect("existing", [material, "--screenshot", existing], 1,
           f"{existing}: already exists")
    with open(existing, "rb") as f:
        if f.read() != b"not replaced":
            failures.append("an existing PNG was replaced without --force")

    # A file that does not load: its name said once (it was "bad.json: bad.json: member ...").
    bad = os.path.join(d, "bad.json")
    with open(bad, "w") as f:
        f.write('{"model": "bogus"}')
    code, err = run([bad, "--screenshot", os.path.join(d, "bad.png")])
    if code != 1 or err.count(bad) != 1 or "member 'model'" not in err:
        failures.append(f"load error: exit {code}, {err!r}")

for f in failures:
    print("FAIL:", f)
print("ok" if not failures else f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
