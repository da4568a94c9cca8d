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

__all__ = ["open", "info", "read_capture", "Source", "Error", "FormatError", "InvalidArgument",
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
