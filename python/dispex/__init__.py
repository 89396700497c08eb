"""dispex: Ptex displacement maps from a Catmull-Clark base cage and its sculpt.

The library's commands from Python, with the command line's options as keyword arguments
(named as the library's fields or as the command line spells them: tolerance=0.001,
oversample="auto", uv_maps="uv") and its errors: TypeError for a value of the wrong type,
ValueError for a value out of range or an unknown option, and for every other failure a
subclass of dispex.Error by its cause (InputError, MismatchError, VerifyError, ...), each with
the library's one-line message and the file or face it is about. See docs/PYTHON.md.

    import dispex
    report = dispex.extract("base.obj", "sculpt.obj", "out.ptx", tolerance=0.001)
    with dispex.Map("out.ptx") as m:
        texels = m.texels(0)                     # (vres, ures, channels) float32
        values = m.sample([0, 1], [0.5, 0.5], [0.5, 0.5])
"""

import os

from . import _dispex
from ._dispex import Map, Mesh, UvMap, __version__
from ._errors import (CancelledError, Error, InputError, MemoryBudgetError, MismatchError,
                      OutputError, VerifyError, shown as _shown)
from . import _options

__all__ = ["CancelledError", "Error", "InputError", "Map", "MemoryBudgetError", "Mesh",
           "MismatchError", "OutputError", "UvMap", "VerifyError", "__version__", "extract",
           "extract_manifest", "info", "make_sculpt", "merge", "option_names", "read_mesh",
           "verify"]


def _path(value, argument):
    if isinstance(value, (str, bytes, os.PathLike)):
        path = os.fsdecode(os.fspath(value))
        if not path:
            raise ValueError(f"{argument}: empty path")
        return path
    raise TypeError(f"{argument}: {_shown(value)} is not a path (str or os.PathLike)")


def _mesh_or_path(value, argument):
    """A dispex.Mesh, a dict of its arrays (named in errors as argument.array), or a path."""
    if isinstance(value, Mesh):
        return value
    if isinstance(value, dict):
        arrays = dict(value)
        try:
            points = arrays.pop("points")
            counts = arrays.pop("face_vertex_counts")
            indices = arrays.pop("face_vertex_indices")
        except KeyError as missing:
            raise ValueError(f"{argument}: no {missing.args[0]} array") from None
        unknown = sorted(set(arrays) - _MESH_KEYWORDS)
        if unknown:
            raise ValueError(f"{argument}: unknown array {unknown[0]!r} (known: points, "
                             f"face_vertex_counts, face_vertex_indices, "
                             f"{', '.join(sorted(_MESH_KEYWORDS))})")
        return Mesh(points, counts, indices, _argument=argument, **arrays)
    if isinstance(value, (str, bytes, os.PathLike)):
        return _path(value, argument)
    raise TypeError(f"{argument}: {_shown(value)} is neither a path, a dispex.Mesh nor a dict of "
                    f"mesh arrays")


_MESH_KEYWORDS = set(_dispex._mesh_keywords())  # Mesh's keyword-only arguments


def _check_progress(progress):
    if progress is not None and not callable(progress):
        raise TypeError(f"progress: {_shown(progress)} is not callable")


def option_names():
    """The extract options by name, each with its command-line flag, the kind of value it
    takes, what it takes in words, its one-line help and default as `dispex extract --help`
    shows them: {name: {"flag", "kind", "values", "help", "default", "in_manifest",
    "in_map"}}; in_map: recorded in the map, so that changing it re-extracts an incremental
    run (threads, max_memory and the like are not)."""
    return {name: {k: v for k, v in spec.items() if k != "name"}
            for name, spec in _options.SPECS.items()}


def read_mesh(path):
    """Reads an OBJ or PLY file into a dispex.Mesh (named by its path).

    Raises dispex.InputError (its path: the file) when the file cannot be read or is malformed.
    """
    return _dispex.read_mesh(_path(path, "path"))


def extract(base, sculpt, output=None, *, out_dir=None, shapes=None, progress=None,
            **options):
    """Extracts the displacement map of `sculpt` over the cage `base`.

    base, sculpt: paths (str or os.PathLike), dispex.Mesh objects, or dicts of a Mesh's
    arrays (points, face_vertex_counts, face_vertex_indices, ...).
    output: the map (.ptx). Returns the report (the JSON report `dispex extract --report`
    writes, as a dict).
    out_dir instead of output: one map per shape of an asset (OBJ o/g groups, docs/SHAPES.md),
    out_dir/<shape>.ptx, base and sculpt as paths; shapes: only these (a list of names).
    Returns the asset's report, its "shapes" a dict {shape name: report}.
    options: every option of `dispex extract`, by the library's field name or the flag's
    spelling (uv_maps="uv" is uv_maps_dir="uv"); option_names() lists them. shard="I/N" writes
    a farm shard's part (docs/FARM.md).
    progress: called as progress(done, total) (Ptex faces; shapes for an asset) at most ten
    times a second, once total is known. Ctrl-C (KeyboardInterrupt) or an exception raised by
    progress cancels the extraction; nothing is written then. The GIL is released while it
    runs.
    """
    _check_progress(progress)
    values = _options.to_json(options)
    if (output is None) == (out_dir is None):
        raise ValueError("give either output (a map) or out_dir (one map per shape)")
    if out_dir is not None:
        return _dispex._extract_asset(_path(base, "base"), _path(sculpt, "sculpt"), None,
                                      _path(out_dir, "out_dir"), _shape_list(shapes), progress,
                                      values)
    if shapes is not None:
        raise ValueError("shapes: only with out_dir (one map per shape)")
    base, sculpt = _mesh_or_path(base, "base"), _mesh_or_path(sculpt, "sculpt")
    if "shard" in values and (isinstance(base, Mesh) or isinstance(sculpt, Mesh)):
        raise ValueError("shard: base and sculpt must be paths (the merge reads them again)")
    return _dispex._extract(base, sculpt, _path(output, "output"), progress, values)


def _shape_list(shapes):
    if shapes is None:
        return []
    if isinstance(shapes, str) or not all(isinstance(s, str) for s in shapes):
        raise TypeError(f"shapes: {_shown(shapes)} is not a list of shape names")
    return list(shapes)


def extract_manifest(manifest, out_dir=None, *, shapes=None, progress=None, **options):
    """Extracts the shapes a manifest names (docs/SHAPES.md: each shape from its own files with
    its own options), one map per shape, as `dispex extract --manifest` does.

    out_dir: overrides the manifest's output_dir. options: apply under the manifest's own.
    Returns the asset's report, its "shapes" a dict {shape name: report}.
    """
    _check_progress(progress)
    values = _options.to_json(options)
    return _dispex._extract_asset(None, None, _path(manifest, "manifest"),
                                  None if out_dir is None else _path(out_dir, "out_dir"),
                                  _shape_list(shapes), progress, values)


def merge(parts, output, *, progress=None, threads=0, max_memory=0):
    """Merges the parts of all shards of one extraction (extract(..., shard="I/N")) into
    `output`: byte for byte the map the extraction without shards writes. parts: paths, in any
    order. Raises dispex.MismatchError naming the part when one is missing, given twice, or
    made from other inputs, options or version; nothing is written then. Returns the report (a
    dict). progress, Ctrl-C: as for extract.
    """
    _check_progress(progress)
    if isinstance(parts, (str, bytes, os.PathLike)):
        raise TypeError(f"parts: {_shown(parts)} is one path, not a list of parts")
    paths = [_path(part, f"parts[{i}]") for i, part in enumerate(parts)]
    limits = _options.to_json({"threads": threads, "max_memory": max_memory})
    return _dispex._merge(paths, _path(output, "output"), progress, limits)


def verify(base, sculpt, map, *, check=True, **options):
    """Measures `map` over `base` against `sculpt` (None: none) and/or a truth file (truth=PATH).

    options: samples_per_face, max_sculpt_points, max_error, max_error_rel, max_rms,
    max_p99, max_mean_tolerances, tolerance, truth_local_bound, truth_local_tolerance_factor,
    truth_rms_factor, truth_p99_factor, max_edge_step, max_edge_step_p99, threads. Returns the
    report (a dict); a map that fails a bound raises dispex.VerifyError, whose report is that
    report, unless check=False.
    """
    if "truth" in options:
        options["truth"] = _path(options["truth"], "truth")
    return _dispex._verify(_path(base, "base"),
                           None if sculpt is None else _path(sculpt, "sculpt"),
                           _path(map, "map"), bool(check), options)


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

    faces: a map's face_list too; strict: a mesh's validation warnings raise dispex.InputError.
    """
    return _dispex._info(_path(path, "path"), bool(faces), bool(strict))
