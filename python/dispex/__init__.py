"""dispex: Ptex displacement maps from a Catmull-Clark base cage and its sculpt.

The library's commands from Python, with the command line's options (as keyword arguments,
named as the library's fields: tolerance=0.001, oversample="auto", resolution_rule="bound")
and its errors (ValueError for bad arguments, dispex.Error for failures, each with the
library's one-line message). See docs/PYTHON.md.

    import dispex
    report = dispex.extract("base.obj", "sculpt.obj", "out.ptx", tolerance=0.001)
    m = dispex.Map("out.ptx")
    texels = m.texels(0)                         # (vres, ures, channels) float32
    values = m.sample([0, 1], [0.5, 0.5], [0.5, 0.5])
"""

import os

from ._dispex import Error, Map, Mesh, __version__, read_mesh as _read_mesh
from . import _dispex

__all__ = ["Error", "Map", "Mesh", "__version__", "extract", "info", "make_sculpt", "merge",
           "read_mesh", "verify"]


def _path(value, argument):
    if isinstance(value, (str, bytes, os.PathLike)):
        path = os.fsdecode(os.fspath(value))
        if not path:
            raise ValueError(f"{argument}: empty path")
        return path
    raise ValueError(f"{argument}: {value!r} is not a path")


def _mesh_or_path(value, argument):
    """A dispex.Mesh, a dict of its arrays (named in errors as argument.array), or a path."""
    if isinstance(value, Mesh):
        return value
    if isinstance(value, dict):
        arrays = dict(value)
        try:
            return Mesh(arrays.pop("points"), arrays.pop("face_vertex_counts"),
                        arrays.pop("face_vertex_indices"), _argument=argument, **arrays)
        except KeyError as missing:
            raise ValueError(f"{argument}: no {missing.args[0]} array") from None
        except TypeError as wrong:
            raise ValueError(f"{argument}: {wrong}") from None
    return _path(value, argument)


def _check_progress(progress):
    if progress is not None and not callable(progress):
        raise ValueError(f"progress: {progress!r} is not callable")


def read_mesh(path):
    """Reads an OBJ or PLY file into a dispex.Mesh (named by its path)."""
    return _read_mesh(_path(path, "path"))


def extract(base, sculpt, output, *, progress=None, **options):
    """Extracts the displacement map of `sculpt` over the cage `base` into `output` (.ptx).

    base, sculpt: paths, dispex.Mesh objects, or dicts of a Mesh's arrays (points,
    face_vertex_counts, face_vertex_indices, ...). options: as `dispex extract` takes them,
    by the library's names (oversample, max_oversample, min_oversample, search_distance,
    ray_policy, tolerance, tolerance_fraction, resolution_rule, fixed_resolution,
    nonzero_threshold, data_type, compression_level, holes, watertight, max_miss_fraction,
    bvh_quality, method, vector, threads, max_memory, incremental, shard="I/N",
    shard_sculpt="whole"|"part": a farm shard's part, docs/FARM.md). progress: called as
    progress(done, total) (Ptex faces) at most ten times a second. Returns the report (the
    JSON report as a dict). Ctrl-C (KeyboardInterrupt) or an exception raised by `progress`
    cancels the extraction; nothing is written then. The GIL is released while it runs.
    """
    _check_progress(progress)
    base, sculpt = _mesh_or_path(base, "base"), _mesh_or_path(sculpt, "sculpt")
    if "shard" in options and (isinstance(base, Mesh) or isinstance(sculpt, Mesh)):
        raise ValueError("shard: base and sculpt must be paths (the merge reads them again)")
    return _dispex._extract(base, sculpt, _path(output, "output"), progress, options)


def merge(parts, output, *, progress=None, threads=0, max_memory=0):
    """Merges the parts of all shards of one extraction (extract(..., shard="I/N")) into
    `output`: byte for byte the map the extraction without shards writes. parts: paths, in any
    order. Raises dispex.Error naming the part when one is missing, given twice, or made from
    other inputs, options or version; nothing is written then. Returns the report (a dict).
    progress, Ctrl-C: as for extract.
    """
    _check_progress(progress)
    if isinstance(parts, (str, bytes, os.PathLike)):
        raise ValueError(f"parts: {parts!r} is one path, not a list of parts")
    paths = [_path(part, f"parts[{i}]") for i, part in enumerate(parts)]
    return _dispex._merge(paths, _path(output, "output"), progress,
                          {"threads": threads, "max_memory": max_memory})


def verify(base, sculpt, map, *, check=True, **options):
    """Measures `map` over `base` against `sculpt` (None: none) and/or a truth file (truth=PATH).

    options: samples_per_face, max_sculpt_points, max_error, max_error_rel, max_rms,
    max_p99, max_mean_tolerances, tolerance, truth_local_bound, truth_local_tolerance_factor,
    truth_rms_factor,
    truth_p99_factor, max_edge_step, max_edge_step_p99, threads. Returns the report (a dict);
    a map that fails a bound raises dispex.Error, unless check=False.
    """
    if "truth" in options:
        options["truth"] = _path(options["truth"], "truth")
    return _dispex._verify(_path(base, "base"),
                           None if sculpt is None else _path(sculpt, "sculpt"),
                           _path(map, "map"), check, options)


def make_sculpt(cage, output, **options):
    """Writes a test sculpt of `cage` with a known displacement, and its truth file.

    options: levels, layout ("refined", "jittered"), density, pattern ("smooth", "detail",
    "ridges", "noise", "none", "sideways", "overhang", "image:FILE.png"), amplitude, seed,
    truth (path; default output + ".truth"), threads. Returns a summary dict.
    """
    if "truth" in options:
        options["truth"] = _path(options["truth"], "truth")
    return _dispex._make_sculpt(_path(cage, "cage"), _path(output, "output"), options)


def info(path, *, faces=False, strict=False):
    """The summary `dispex info --json` prints of a mesh (OBJ, PLY), a Ptex map or a UV-space
    map tile (.exr), as a dict.

    faces: a map's face_list too; strict: a mesh's validation warnings raise dispex.Error.
    """
    return _dispex._info(_path(path, "path"), bool(faces), bool(strict))
