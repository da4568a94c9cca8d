"""What the engine hand-off's Python checks share: a failure list that collects every failed
check (the script then exits 1 naming them all), running a tool that must succeed and the
scripts' ending (exit code, work folder kept or removed)."""
import shutil
import subprocess
import sys

FAILURES = []


def expect(condition, message):
    """Records `message` as a failure (and prints it) unless `condition` holds."""
    if not condition:
        FAILURES.append(message)
        print("FAIL " + message)


def run(cmd, **kw):
    """Runs `cmd`; on a non-zero exit prints the command, its output and the end of its stderr
    and exits 1. Returns its stdout."""
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        print(f"FAILED ({r.returncode}): {' '.join(cmd)}\n{r.stdout}\n{r.stderr[-4000:]}")
        sys.exit(1)
    return r.stdout


def finish(work, keep):
    """The script's exit code: 1 if a check failed, else 0. The work folder is kept (and named)
    when a check failed or with `keep`, else removed."""
    if FAILURES or keep:
        print(f"{len(FAILURES)} check(s) failed; kept {work}")
        return 1 if FAILURES else 0
    shutil.rmtree(work, ignore_errors=True)
    return 0
