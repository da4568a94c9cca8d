"""brdf: evaluate BRDF measurements, captures, LUTs and library materials from numpy.

    import brdf, numpy as np
    gold = brdf.open("gold")                 # a library material, or any file `brdf eval` opens
    f = gold.eval_deg(30, 0, np.linspace(0, 80, 81), 180)   # (81, 3) f_r in 1/sr, RGB

Values are those `brdf eval` gives for the same file, bit for bit (the same library call).
Errors raise brdf.IoError (an OSError) for missing or unreadable files, brdf.FormatError or
brdf.InvalidArgument (ValueErrors) for bad content, shapes and dtypes, with the one-line
message the command-line tool prints after "brdf: error: ".
"""

import os as _os

import numpy as _np

from . import _paths

# An installed package finds the material library relative to itself (the interpreter is not
# installed beside it), through the variable the library reads; a value the user set wins.
if _paths.MATERIALS_FROM_PACKAGE is not None and not _os.environ.get("BRDF_MATERIALS_DIR"):
    _os.environ["BRDF_MATERIALS_DIR"] = _os.path.normpath(
        _os.path.join(_os.path.dirname(_os.path.abspath(__file__)), _paths.MATERIALS_FROM_PACKAGE))

from ._brdf import Error, FormatError, InvalidArgument, IoError
from ._brdf import Source as _Source

__all__ = ["open", "info", "read_capture", "write_capture", "Source", "Error", "FormatError", "InvalidArgument",
           "IoError"]


class Source:
    """One opened file or library material (brdf.open)."""

    def __init__(self, path_or_name):
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
