"""brdf: evaluate BRDF measurements, captures, LUTs and library materials from numpy.

    import brdf, numpy as np
    gold = brdf.open("gold")                 # a library material, or any file `brdf eval` opens
    f = gold.eval_deg(30, 0, np.linspace(0, 80, 81), 180)   # (81, 3) f_r in 1/sr, RGB

Values are those `brdf eval` gives for the same file, bit for bit (the same library call).
The other calls answer as the `brdf` commands of the same names do, through the same library
entry points: info (`brdf info --json`), read_capture / write_capture (.bpc captures), fit,
convert, preview and capture (the simulated instrument). docs/python.md has a worked example.
Errors raise brdf.IoError (an OSError) for missing or unreadable files, brdf.FormatError or
brdf.InvalidArgument (ValueErrors) for bad content, shapes and dtypes, with the one-line
message the command-line tool prints after "brdf: error: ".
"""

import os as _os

import numpy as _np

from . import _paths

# An installed package finds the material library and the modules (the image reader) relative
# to itself (the interpreter is not installed beside it), through the variables the library
# reads; a value the user set wins.
for _variable, _relative in (("BRDF_MATERIALS_DIR", _paths.MATERIALS_FROM_PACKAGE),
                             ("BRDF_MODULE_DIR", _paths.MODULES_FROM_PACKAGE)):
    if _relative is not None and not _os.environ.get(_variable):
        _os.environ[_variable] = _os.path.normpath(
            _os.path.join(_os.path.dirname(_os.path.abspath(__file__)), _relative))
del _variable, _relative

from ._brdf import Error, FormatError, InvalidArgument, IoError
from ._brdf import Source as _Source

__all__ = ["open", "info", "read_capture", "write_capture", "fit", "convert", "preview", "capture", "Source", "Error", "FormatError", "InvalidArgument",
           "IoError"]


class Source:
    """One opened file or library material (brdf.open)."""

    def __init__(self, path_or_name):
        """Opens the file or library material (brdf.open)."""
        self._source = _Source(str(path_or_name))

    @property
    def path(self):
        """The path or library name given to brdf.open."""
        return self._source.path

    @property
    def name(self):
        """The source's short name ("gold", "paper_white_rgb.bsdf")."""
        return self._source.name

    @property
    def evaluation(self):
        """How values are computed: "analytic", "measured_database", "resampled_lut",
        "exported_lut" (see docs/python.md)."""
        return self._source.evaluation

    @property
    def warnings(self):
        """The warnings opening the file gave (the lines `brdf eval` prints on stderr)."""
        return list(self._source.warnings)

    @property
    def measured_theta_in_deg(self):
        """The measured light polar angles of a capture or LUT (empty for other sources)."""
        return list(self._source.measured_theta_in_deg)

    def info(self):
        """What the file holds: the document `brdf info --json` prints for it, as a dict
        (brdf.info(path) describes a file without opening it for evaluation, damaged captures
        included)."""
        return info(self._source.path)

    def eval(self, wi, wo, jobs=0):
        """f_r (1/sr, RGB, not multiplied by cos) for N pairs of unit vectors.

        wi, wo: float64 arrays of shape (N, 3) in the local frame (z = normal); wi points towards
        the light, wo towards the viewer. Returns a float64 array of shape (N, 3).
        jobs: threads for batches of 16,384 pairs or more (0: one per core), as `--jobs`.
        """
        return self._source.eval(_np.asarray(wi), _np.asarray(wo), int(jobs))

    def eval_deg(self, theta_in, phi_in, theta_out, phi_out, jobs=0):
        """f_r (1/sr, RGB) for angles in degrees, as `brdf eval --in T,P --out T,P` gives it.

        The four arguments are numbers or arrays broadcast against each other (numpy rules);
        polar angles in [0, 90], azimuths finite. Returns float64 of shape broadcast + (3,).
        jobs: threads for batches of 16,384 pairs or more (0: one per core).
        """
        names = ("theta_in", "phi_in", "theta_out", "phi_out")
        arrays = []
        for name, value in zip(names, (theta_in, phi_in, theta_out, phi_out)):
            a = _np.asarray(value)
            if a.dtype.kind not in "fiu":
                raise InvalidArgument(
                    f"{name}: expected real numbers (degrees), got dtype {a.dtype}")
            arrays.append(a)
        try:
            broadcast = _np.broadcast_arrays(*arrays)
        except ValueError:
            shapes = ", ".join(str(a.shape) for a in arrays)
            raise InvalidArgument(
                f"eval_deg: the angle arrays do not broadcast together, got shapes {shapes}"
            ) from None
        shape = broadcast[0].shape
        flat = [_np.ascontiguousarray(a, dtype=_np.float64).reshape(-1) for a in broadcast]
        return self._source._eval_deg_flat(*flat, int(jobs)).reshape(shape + (3,))

    def __repr__(self):
        """brdf.Source('path', evaluation='...')."""
        return f"brdf.Source({self.path!r}, evaluation={self.evaluation!r})"


def open(path_or_name):  # noqa: A001 (the module's entry point, like io.open)
    """Opens any file `brdf eval` evaluates (material .json, .bpc capture, .ktx2/.dds LUT or
    sidecar, RGL .bsdf, MERL .binary, tables) or a library material name ("gold")."""
    return Source(path_or_name)


def info(path_or_name):
    """The description `brdf info --json` prints for a file or library material, as a dict:
    the same keys and values (statistics of every slice, metadata, header fields, "usable" and
    "refusals" for captures and tables, warnings), non-finite statistics as None. Remedies in
    the text ("advice", refusals) are phrased for Python (docs/python.md, "Errors"); files that
    cannot be read at all raise as brdf.open does."""
    import json
    from ._brdf import describe
    return json.loads(describe(str(path_or_name)))


def read_capture(path):
    """The samples of a .bpc capture as numpy arrays, read as `brdf export-csv` reads it
    (damage is refused with the CLI's message; an interrupted slice is kept, flagged).

    Returns a dict: "theta_in_deg", "phi_in_deg", "theta_out_deg", "phi_out_deg" (float32, N),
    "rgb" and "sigma" (float32, N×3, f_r and its one-sigma uncertainty in 1/sr; sigma 0 where
    the slice records none), "flags" (uint8, N: bit 0 saturated, 1 below the noise floor,
    2 interpolated, 3 invalid), "slice" (int32, N: index into "slices"), "slices" (one dict per
    slice: theta_in_deg, phi_in_deg, has_sigma, complete, samples), "metadata" (the file's
    metadata, "extra" for any other key) and "warnings".
    """
    from ._brdf import read_capture as _read_capture
    return _read_capture(str(path))


def _real_array(value, name, shape_text, ndim, n=None):
    """`value` as a C-contiguous float32 array of `ndim` dimensions (N, or N×3), or
    InvalidArgument in the style of the other shape messages."""
    a = _np.asarray(value)
    if a.dtype.kind not in "fiu":
        raise InvalidArgument(f"{name}: expected {shape_text} of real numbers, got dtype {a.dtype}")
    ok = a.ndim == ndim and (ndim == 1 or a.shape[1] == 3) and (n is None or a.shape[0] == n)
    if not ok:
        length = "" if n is None else f" (N = {n}, the length of theta_in)"
        raise InvalidArgument(f"{name}: expected {shape_text}{length}, got shape {a.shape}")
    return _np.ascontiguousarray(a, dtype=_np.float32)


def write_capture(path, theta_in, phi_in, theta_out, phi_out, rgb, sigma=None, flags=None,
                  metadata=None, overwrite=False):
    """Writes samples measured elsewhere as a .bpc capture that every `brdf` command and
    brdf.open read like one the instrument made.

    theta_in, phi_in, theta_out, phi_out: N angles in degrees (light and view directions;
    θin in [0, 90), θout in [0, 90], azimuths finite). rgb: N×3 f_r in 1/sr, linear RGB, not
    multiplied by cos θ. sigma: N×3 one-sigma uncertainties, or None (none recorded). flags:
    N integers, bits 0-3 (1 saturated, 2 below the noise floor, 4 interpolated, 8 invalid), or
    None (all 0). Numbers are stored as float32, the format's precision (read_capture returns
    float32, so its arrays round-trip bit for bit). Consecutive samples of one light direction
    (θin, φin) form one slice, in the order given.
    metadata: a dict with any of the keys read_capture returns ("sample_name",
    "instrument_model", ..., "extra": a dict of text); software_version defaults to this
    toolchain's.
    The file is written as every brdf command writes a whole file: to a temporary sibling,
    flushed to disk and renamed into place, so a crash leaves either no file or the complete
    one; an existing file is replaced only with overwrite=True. Returns the number of slices.
    Wrong shapes, dtypes or values raise brdf.InvalidArgument (a ValueError) naming the
    argument and, for values, the index.
    """
    t_in = _real_array(theta_in, "theta_in", "a 1-D array (N)", 1)
    n = t_in.shape[0]
    if n == 0:
        raise InvalidArgument("theta_in: expected at least one sample, got an empty array")
    one_d = "a 1-D array (N)"
    p_in = _real_array(phi_in, "phi_in", one_d, 1, n)
    t_out = _real_array(theta_out, "theta_out", one_d, 1, n)
    p_out = _real_array(phi_out, "phi_out", one_d, 1, n)
    c = _real_array(rgb, "rgb", "an N×3 array", 2, n)
    e = None if sigma is None else _real_array(sigma, "sigma", "an N×3 array", 2, n)
    if flags is None:
        f = _np.zeros(n, dtype=_np.uint8)
    else:
        f = _np.asarray(flags)
        if f.dtype.kind not in "iu":
            raise InvalidArgument(f"flags: expected a 1-D array (N) of integers, got dtype {f.dtype}")
        if f.ndim != 1 or f.shape[0] != n:
            raise InvalidArgument(
                f"flags: expected a 1-D array (N) (N = {n}, the length of theta_in), got shape {f.shape}")
        bad = _np.nonzero((f < 0) | (f > 15))[0]
        if bad.size:
            i = int(bad[0])
            raise InvalidArgument(
                f"flags[{i}]: expected bits 0-3 only (saturated 1, below noise floor 2, "
                f"interpolated 4, invalid 8), got {int(f[i])}")
        f = _np.ascontiguousarray(f, dtype=_np.uint8)
    if metadata is None:
        metadata = {}
    if not isinstance(metadata, dict):
        raise InvalidArgument(f"metadata: expected a dict, got {type(metadata).__name__}")
    from ._brdf import write_capture as _write_capture
    return _write_capture(_os.fspath(path), t_in, p_in, t_out, p_out, c, e, f, metadata,
                          bool(overwrite))


def _tools():
    """The compiled fit/convert/preview/capture part, loaded on first use (it links Ceres, the
    previewer and the USB stack, which `import brdf` does not need)."""
    from . import _brdf_tools
    return _brdf_tools


def _path_of(source_or_path):
    """The path (or library name) a brdf.Source was opened with, or the argument as a path."""
    return source_or_path.path if isinstance(source_or_path, Source) else _os.fspath(source_or_path)


def _warn(lines):
    """Issues the CLI's stderr warning lines as Python UserWarnings."""
    import warnings
    for line in lines:
        warnings.warn(line, UserWarning, stacklevel=3)


def _extrapolation_text(extrapolate):
    """None, "P,L" or (p, l) as the text `--extrapolate` takes ("" for none)."""
    if extrapolate is None:
        return ""
    if isinstance(extrapolate, str):
        return extrapolate
    try:
        p, l = extrapolate
    except (TypeError, ValueError):
        raise InvalidArgument(
            f"extrapolate: expected (p, l) or 'P,L', got {extrapolate!r}") from None
    return f"{float(p)!r},{float(l)!r}"


def fit(source_or_path, model="ggx", loss="ngan", robust=False, max_theta_out=None, starts=2,
        jobs=0):
    """Fits an analytic model, as `brdf fit INPUT --model MODEL --loss LOSS --out FILE.json`
    does, and returns the material file that command writes, as a dict: the model's
    parameters, "name", "model" and the report under "fit" (status, RMSE overall and per θin
    slice, median relative error, warnings). The same input gives the same numbers as the CLI.

    source_or_path: a brdf.Source, a file (capture, material, RGL, MERL, exported LUT, table)
    or a library material name. model: a model name of `brdf fit --model` ("ggx", "lambert",
    ...; one model per call). loss: "ngan", "log" or "cbrt". robust, max_theta_out (degrees),
    starts: as `--robust`, `--max-theta-out`, `--starts`. jobs: Ceres' threads (0: one per
    core); the result does not depend on it. Warnings opening the input are issued as Python
    UserWarnings (the lines the CLI prints on stderr).
    """
    import json
    text, warnings = _tools().fit(_path_of(source_or_path), str(model), str(loss), bool(robust),
                                  0.0 if max_theta_out is None else float(max_theta_out),
                                  int(starts), int(jobs))
    _warn(warnings)
    return json.loads(text)


def convert(source_or_path, out_dir, formats="ktx2,dds,exr,png,json", extrapolate=None,
            beyond=None, beyond_subdivide=None, exr_type="float", exr_compression="none",
            overwrite=False, jobs=0):
    """Writes the engine-ready LUT of a capture or material file, as
    `brdf convert INPUT --out OUT_DIR` does for one input (same library call, same files, byte
    for byte), and returns the paths written (order: ktx2, dds, exr, png, json).

    formats: the comma-separated list of `--formats`. extrapolate: (p, l) or "P,L" for the
    grazing-angle extrapolation (`--extrapolate P,L`; default: the input's own choice, else
    1, 0.5). beyond, beyond_subdivide: the blind-spot fill of `--beyond` / `--beyond-subdivide`
    (default: the command's). exr_type ("float", "half") and exr_compression ("none", "zip"):
    `--exr-type`, `--exr-compression`. Existing outputs are replaced only with overwrite=True;
    every file is written atomically, and a failure removes the outputs the call created (a
    file it replaced keeps its new content). Warnings (saturated
    samples, ...) are issued as UserWarnings. Engine hand-offs and `--extrapolate auto` are
    the CLI's (`brdf convert --engine ...`).
    """
    written, warnings = _tools().convert(
        _path_of(source_or_path), _os.fspath(out_dir), str(formats),
        _extrapolation_text(extrapolate), "" if beyond is None else str(beyond),
        0 if beyond_subdivide is None else int(beyond_subdivide), str(exr_type),
        str(exr_compression), bool(overwrite), int(jobs))
    _warn(warnings)
    return list(written)


def _angle_pair(value, name):
    """None or (theta, phi) in degrees as two floats; InvalidArgument naming `name` otherwise."""
    if value is None:
        return None
    try:
        a, b = value
        return float(a), float(b)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{name}: expected (theta, phi) in degrees, got {value!r}") from None


def preview(source_or_path, size=512, env=None, env_rotation=0.0, mesh="sphere", light=None,
            view=None, fov=0.0, estimator="auto", spp=None, rms=0.0, subdivisions=2, seed=1,
            jobs=0, background=True, extrapolate=None):
    """Renders a source under an environment map, as `brdf preview SOURCE --out IMAGE.exr`
    does with the same options, and returns the image that command writes to the .exr: a
    float32 array of shape (size, size, 3), linear radiance, row 0 at the top (no tone map;
    for display, e.g. plt.imshow(np.clip(img, 0, 1) ** (1 / 2.2))).

    env: "studio" (default), "sky", "furnace", "axes" or an .exr/.hdr file (`--env`);
    env_rotation (degrees), mesh ("sphere", "plane" or a .ply/.obj file), view and light
    ((theta, phi) in degrees; with a light and no env the light alone illuminates, as
    `--light`), fov (degrees, > 0: perspective), estimator ("auto", "hierarchical", "mis",
    "env", "brdf", "quadrature"), spp (passes; giving it selects Monte Carlo as `--spp`), rms
    (target relative error), subdivisions, seed, jobs (0: one thread per core), background
    (False: black where the object is not), extrapolate ((p, l) or "P,L" for captures).
    """
    import numpy as np  # noqa: F401 (the result is a numpy array)
    a = _tools().PreviewArguments()
    a.size = int(size)
    a.env = "studio" if env is None else _os.fspath(env)
    a.env_given = env is not None
    a.env_rotation_deg = float(env_rotation)
    a.mesh = _os.fspath(mesh)
    a.light = _angle_pair(light, "light")
    a.view = _angle_pair(view, "view")
    a.fov_deg = float(fov)
    a.estimator = str(estimator)
    a.spp_given = spp is not None
    a.spp = 64 if spp is None else int(spp)
    a.rms = float(rms)
    a.subdivisions = int(subdivisions)
    a.seed = int(seed)
    a.jobs = int(jobs)
    a.background = bool(background)
    a.extrapolate = _extrapolation_text(extrapolate)
    image, warnings = _tools().preview(_path_of(source_or_path), a)
    _warn(warnings)
    return image


def capture(material, out, sample=None, noise=1.0, seed=1, theta_in=(0, 20, 40, 60),
            theta_out_max=75.0, theta_out_step=1.0, phi_out_step=1.0, exposure="auto",
            operator_notes="", resume=False, overwrite=False, calibrate=False):
    """Captures a virtual sample with the simulated instrument, as
    `brdf capture --device sim --material MATERIAL --sample SAMPLE --out OUT` does with the same
    options: the same session (the instrument's wire protocol, calibration, auto-ranged
    exposure, noise from `seed`), the same crash-safe file (each slice flushed to disk as it
    completes) and the same recorded settings, so either can resume the other's capture.

    material: a library name or an evaluable file (the virtual sample). out: the .bpc to
    write. sample: the sample name recorded (default: material). noise: 0 = ideal detector,
    1 = the reference instrument. theta_in, theta_out_max, theta_out_step, phi_out_step:
    the geometry in degrees (defaults: the reference instrument's). exposure: "auto" (per
    θout row), "auto-slice" or milliseconds. resume: continue an interrupted capture in
    `out`; overwrite: replace an existing file (with resume: accept a different instrument);
    calibrate: with resume, measure new dark and white references.
    Returns a dict: path, finished, resumed, slices_planned, slices_saved, new_samples,
    saturated, below_noise_floor, message, warnings. Ctrl-C stops the capture
    (KeyboardInterrupt): the completed slices are in the file, a valid unfinished capture that
    resume=True (or `brdf capture --resume`) completes.
    """
    t = _tools()
    a = t.CaptureArguments()
    a.material = _path_of(material)
    a.out = _os.fspath(out)
    a.sample = a.material if sample is None else str(sample)
    a.operator_notes = str(operator_notes)
    a.noise = _checked_number(noise, "noise", lambda v: v >= 0,
                              "a level ≥ 0 (1 = reference instrument)")
    a.seed = int(seed)
    angles = [float(v) for v in _np.atleast_1d(_np.asarray(theta_in, dtype=float))]
    if not angles:
        raise InvalidArgument("theta_in: at least one angle is required")
    for v in angles:
        if not (0 <= v < 90):
            raise InvalidArgument(f"theta_in: angles must be in [0, 90) degrees, got {v:g}")
    a.theta_in_deg = angles
    a.theta_out_max_deg = _checked_number(theta_out_max, "theta_out_max", lambda v: 0 <= v < 90,
                                          "[0, 90) degrees")
    a.theta_out_step_deg = _checked_number(theta_out_step, "theta_out_step",
                                           lambda v: 0.01 <= v <= 90, "[0.01, 90] degrees")
    a.phi_out_step_deg = _checked_number(phi_out_step, "phi_out_step",
                                         lambda v: 0.01 <= v <= 360, "[0.01, 360] degrees")
    text = str(exposure)
    a.exposure = text
    if text in ("auto", "auto-row"):
        a.exposure_mode = 0
    elif text == "auto-slice":
        a.exposure_mode = 1
    else:
        try:
            ms = float(text)
        except ValueError:
            ms = float("nan")
        if not (ms > 0 and ms < float("inf")):
            raise InvalidArgument(
                f"exposure: expected auto, auto-slice or a time in ms, got {text!r}")
        a.exposure_mode, a.exposure_ms = 2, ms
    a.resume, a.overwrite, a.calibrate = bool(resume), bool(overwrite), bool(calibrate)
    result = t.capture(a)
    _warn(result["warnings"])
    return result


def _checked_number(value, name, rule, expected):
    """`value` as a float satisfying `rule`, else InvalidArgument "<name>: expected ..."."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{name}: expected {expected}, got {value!r}") from None
    if not (rule(v) and v == v):
        raise InvalidArgument(f"{name}: expected {expected}, got {v:g}")
    return v
