"""fiblet: compressed tractograms (.fft) decoded straight into numpy.

    import fiblet
    s = fiblet.load("sub-01_tracks.fft")        # all fibers
    s.points        # (N, 3) float32, world millimetres (RAS+, as in .tck)
    s.offsets       # (F + 1,) int64: fiber i is points[offsets[i]:offsets[i + 1]]
    s.lengths       # (F,) int64 points per fiber
    s[i]            # the (n_i, 3) points of fiber i (a view)
    s[10:20], s[[3, 1]], s[s.lengths > 100]   # Streamlines, as ArraySequence
    fiblet.load("t.fft", roi=(0, 0, 0, 10))       # sphere x,y,z,r (or a box, a mask)
    fiblet.load("t.fft", roi=fiblet.Mask("wm.nii.gz"))
    s, data = fiblet.load("t.fft", data=True)     # + {"dps/NAME": (F, c), "dpv/NAME": (N, c), "groups/NAME": ...}
    sft = fiblet.load_sft("t.fft", "t1.nii.gz")   # DIPY StatefulTractogram (reference="same": the .trk's space)

    tractogram = fiblet.load_tractogram("tracks.fft")   # nibabel Tractogram
    fiblet.save("out.fft", tractogram.streamlines)      # from nibabel, lists, ...
    fiblet.save("out.trk", s)       # the format its name says: .fft, .fftz, .tck, .trk, .trx
    fiblet.stats("out.fft", "in.tck")                   # measured error

The decoded points are handed to numpy without a copy: the arrays own the
decoder's buffers.
"""

# Imports under private names: the package's namespace is its API (__all__).
import numbers as _numbers
import os as _os
import tempfile as _tempfile
from dataclasses import dataclass as _dataclass

import numpy as _np

from . import _fiblet
from ._fiblet import FibletError

__version__ = _fiblet.version
__all__ = [
    "Streamlines", "Sphere", "Box", "Mask", "FibletError",
    "load", "load_array_sequence", "load_tractogram", "load_sft", "read_streamlines", "save", "stats", "info",
]


class Streamlines:
    """Fibers in the TRX layout: one (N, 3) float32 point array and offsets.

    ``fiber_ids`` gives, for each fiber, its index in the file it came from
    (useful after a ``fibers=`` or ``roi=`` selection; -1 for a fiber added
    by :meth:`append` or :meth:`extend`).

    It answers as nibabel's ``ArraySequence`` does (compared member by
    member in python/tests/test_api.py): ``len``, ``s[i]`` (a view),
    ``s[slice | ints | mask]``, iteration, ``_data``, ``_offsets``,
    ``_lengths``, ``get_data()`` (a copy), ``copy()``, ``common_shape``,
    ``total_nb_rows``, ``is_sliced_view``, ``append()``, ``extend()``,
    ``finalize_append()``. Differences:

    - ``offsets`` has F + 1 entries (the TRX layout: fiber i is
      ``points[offsets[i]:offsets[i + 1]]``); nibabel's ``_offsets`` (F
      entries, the first point of each fiber) is ``offsets[:-1]``.
      ``lengths`` and ``_lengths`` are the same (F,) points per fiber.
    - A step-1 slice ``s[a:b]`` is a view whose ``_data`` holds only the
      sliced fibers' points, so its ``_offsets`` start at 0 (nibabel's keep
      the parent's, with ``is_sliced_view`` True; here it is always False).
    - Points are always float32 with 3 columns: appended elements are cast
      to float32 (as nibabel casts into an existing float32 sequence), and
      one of another shape raises ValueError. Appending copies the points
      (the decoded arrays cannot grow in place): ``extend`` copies once, as
      does a series of ``append(x, cache_build=True)`` ended by
      ``finalize_append()``.
    - No arithmetic or comparison operators, ``__setitem__``,
      ``shrink_data``, ``save``/``load``: :meth:`to_array_sequence` gives a
      real ArraySequence sharing the memory.
    """

    __slots__ = ("points", "offsets", "fiber_ids", "_lengths_cache", "_pending")

    def __init__(self, points, offsets, fiber_ids=None):
        self.points = points
        self.offsets = offsets
        self.fiber_ids = _np.arange(len(offsets) - 1) if fiber_ids is None else fiber_ids
        self._lengths_cache = None
        self._pending = None  # elements of append(cache_build=True), until finalize_append()

    @property
    def lengths(self):
        """Points per fiber, (F,) int64."""
        if self._lengths_cache is None:
            self._lengths_cache = _np.diff(self.offsets)
        return self._lengths_cache

    # nibabel's ArraySequence fields.
    @property
    def _data(self):
        """The (N, 3) points (nibabel's ``ArraySequence._data``)."""
        return self.points

    @property
    def _offsets(self):
        """(F,) first point of each fiber in ``_data``: ``offsets[:-1]``."""
        return self.offsets[:-1]

    @property
    def _lengths(self):
        """(F,) points per fiber: ``lengths``."""
        return self.lengths

    @property
    def common_shape(self):
        return self.points.shape[1:]

    @property
    def total_nb_rows(self):
        """Points in all fibers (as nibabel: ``np.sum(_lengths)``)."""
        return _np.sum(self.lengths)

    @property
    def is_sliced_view(self):
        return self.lengths.sum() != self.points.shape[0]

    @property
    def is_array_sequence(self):
        return True

    def get_data(self):
        """A copy of the points of all fibers, (total_nb_rows, 3) float32."""
        return self.points[self.offsets[0]:self.offsets[-1]].copy()

    def copy(self):
        """A Streamlines with its own copy of the points, offsets and fiber_ids."""
        return Streamlines(self.get_data(), self.offsets - self.offsets[0], self.fiber_ids.copy())

    def append(self, element, cache_build=False):
        """Adds one fiber, an (n, 3) array (cast to float32). As nibabel, an
        empty element is not added; with ``cache_build=True`` the fibers are
        added by :meth:`finalize_append`."""
        element = _element(element)
        if element is None:
            return
        if cache_build or self._pending is not None:
            if self._pending is None:
                self._pending = []
            self._pending.append(element)
            return
        self._add([element])

    def finalize_append(self):
        """Adds the fibers of ``append(..., cache_build=True)``."""
        pending, self._pending = self._pending, None
        if pending:
            self._add(pending)

    def extend(self, elements):
        """Adds every element of an iterable of (n, 3) arrays (a list, an
        ArraySequence, a Streamlines, a generator); empty ones are skipped,
        as nibabel does."""
        self.finalize_append()
        self._add([e for e in map(_element, elements) if e is not None])

    def _add(self, elements):
        if not elements:
            return
        lengths = _np.array([len(e) for e in elements], dtype=_np.int64)
        first = self.offsets[0]
        self.points = _np.concatenate([self.points[first:self.offsets[-1]]] + elements)
        self.offsets = _np.concatenate([self.offsets - first, self.offsets[-1] - first + _np.cumsum(lengths)])
        self.fiber_ids = _np.concatenate([self.fiber_ids, _np.full(len(elements), -1, dtype=_np.int64)])
        self._lengths_cache = None

    def __len__(self):
        return len(self.offsets) - 1

    def __getitem__(self, key):
        """An int gives the (n, 3) points of one fiber (a view); a slice, a
        sequence of ints or a boolean mask gives a Streamlines (as nibabel's
        ArraySequence does), whose fiber_ids follow."""
        if isinstance(key, (_numbers.Integral, _np.integer)) and not isinstance(key, (bool, _np.bool_)):
            n = len(self)
            if not -n <= key < n:
                raise IndexError(f"fiber {key} out of range ({n} fibers)")
            i = int(key) % n
            return self.points[self.offsets[i]:self.offsets[i + 1]]
        return self._select(_fiber_indices(key, len(self)))

    def _select(self, ids):
        """The fibers `ids` (an int64 array) as a new Streamlines."""
        if isinstance(ids, slice):  # a step-1 slice: a view of the points
            first, last = self.offsets[ids.start], self.offsets[ids.stop]
            return Streamlines(self.points[first:last], self.offsets[ids.start:ids.stop + 1] - first,
                               self.fiber_ids[ids])
        lengths = self.lengths[ids]
        offsets = _np.zeros(len(ids) + 1, dtype=_np.int64)
        _np.cumsum(lengths, out=offsets[1:])
        starts = self.offsets[:-1][ids]
        # Point k of output fiber i comes from starts[i] + k.
        source = _np.repeat(starts - offsets[:-1], lengths) + _np.arange(offsets[-1], dtype=_np.int64)
        return Streamlines(self.points[source], offsets, self.fiber_ids[ids])

    def __iter__(self):
        for i in range(len(self)):
            yield self.points[self.offsets[i]:self.offsets[i + 1]]

    def __repr__(self):
        return f"fiblet.Streamlines({len(self)} fibers, {len(self.points)} points)"

    def to_array_sequence(self):
        """The same fibers as a nibabel ArraySequence sharing this memory."""
        from nibabel.streamlines import ArraySequence

        seq = ArraySequence()
        # nibabel's own loaders fill these three fields the same way; setting
        # them directly avoids a per-fiber copy of the whole tractogram.
        seq._data = self.points
        seq._offsets = self.offsets[:-1]
        seq._lengths = self.lengths
        return seq


def _element(element):
    """One fiber for append/extend: an (n, 3) float32 array, or None when empty."""
    element = _np.asarray(element)
    if element.size == 0:
        return None
    if element.ndim != 2 or element.shape[1] != 3:
        raise ValueError(f"a fiber is an (n, 3) array of points, got shape {element.shape}")
    return element.astype(_np.float32, copy=False)


@_dataclass(frozen=True)
class Sphere:
    """A spherical region (centre and radius in mm) for ``load(roi=...)``."""

    center: tuple
    radius: float
    exclude: bool = False

    def _spec(self):
        c = _vec3(self.center, "Sphere center")
        r = float(self.radius)
        if not r >= 0:
            raise ValueError(f"Sphere radius must be >= 0, got {self.radius!r}")
        return ("sphere", c, (r, 0.0, 0.0), bool(self.exclude))


@_dataclass(frozen=True)
class Box:
    """An axis-aligned box (min and max corners in mm) for ``load(roi=...)``."""

    min: tuple
    max: tuple
    exclude: bool = False

    def _spec(self):
        lo, hi = _vec3(self.min, "Box min"), _vec3(self.max, "Box max")
        if any(a > b for a, b in zip(lo, hi)):
            raise ValueError(f"Box min {lo} exceeds max {hi}")
        return ("box", lo, hi, bool(self.exclude))


@_dataclass(frozen=True)
class Mask:
    """An image mask (.nii, .nii.gz, .mif) for ``load(roi=...)``, with
    MRtrix3 ``tckedit``'s rule: a point is inside when the voxel nearest to
    it holds a value that rounds to non-zero (>= 0.5)."""

    path: str
    exclude: bool = False

    def _spec(self):
        return ("mask", _existing(self.path), None, bool(self.exclude))


def _region_from_numbers(values):
    """x,y,z,r: a sphere; x0,y0,z0,x1,y1,z1: a box (corners in any order)."""
    a = _np.asarray(values, dtype=_np.float64).reshape(-1)
    if a.size == 4:
        return Sphere(tuple(a[:3]), float(a[3]))._spec()
    if a.size == 6:
        return Box(tuple(_np.minimum(a[:3], a[3:])), tuple(_np.maximum(a[:3], a[3:])))._spec()
    raise ValueError(f"a region given as numbers needs 4 (x, y, z, radius) or 6 (two box corners), got {a.size}")


def _is_number(x):
    return isinstance(x, (_numbers.Real, _np.number)) and not isinstance(x, (bool, _np.bool_))


def _region_spec(r):
    if isinstance(r, (Sphere, Box, Mask)):
        return r._spec()
    if isinstance(r, (str, _os.PathLike)):
        return Mask(r)._spec()
    if isinstance(r, (_np.ndarray, list, tuple)) and all(_is_number(x) for x in _np.asarray(r).reshape(-1)):
        return _region_from_numbers(r)
    raise TypeError(f"a region is a fiblet.Sphere, Box or Mask, an image path, or 4 or 6 numbers; got {r!r}")


def _regions(roi):
    """The (shape, a, b, exclude) tuples the compiled module takes."""
    if roi is None:
        return []
    if isinstance(roi, _np.ndarray):
        if roi.ndim == 1:
            return [_region_from_numbers(roi)]
        if roi.ndim == 2:
            return [_region_from_numbers(row) for row in roi]
        raise ValueError(f"roi as an array must be 1-D (one region) or 2-D (one per row), got shape {roi.shape}")
    if isinstance(roi, (list, tuple)):
        if roi and all(_is_number(x) for x in roi):
            return [_region_from_numbers(roi)]
        return [_region_spec(r) for r in roi]
    return [_region_spec(roi)]


def _fiber_indices(key, count):
    """Fiber positions for a slice, a sequence of ints or a boolean mask:
    a step-1 slice stays a slice (start, stop normalised), else an int64 array."""
    if isinstance(key, (slice, range)):
        start, stop, step = slice(key.start, key.stop, key.step).indices(count)
        if step == 1:
            return slice(start, max(start, stop))
        return _np.arange(start, stop, step, dtype=_np.int64)
    a = _np.asarray(key)
    if a.ndim == 0:
        a = a.reshape(1)
    if a.ndim != 1:
        raise IndexError(f"fiber selection must be 1-D, got shape {a.shape}")
    if a.dtype == bool:
        if len(a) != count:
            raise IndexError(f"boolean mask of {len(a)} values for {count} fibers")
        return _np.flatnonzero(a).astype(_np.int64)
    out_of_range = IndexError(f"fiber index out of range ({count} fibers)")
    if a.dtype == object and all(isinstance(x, _numbers.Integral) and not isinstance(x, bool) for x in a):
        # Python ints beyond int64 (10**30): compared as ints, never cast.
        if any(x < -count or x >= count for x in a):
            raise out_of_range
        a = a.astype(_np.int64)
    if a.size and not _np.issubdtype(a.dtype, _np.integer):
        raise TypeError(f"fibers are selected by ints, a slice or a boolean mask, got {a.dtype} values")
    # Unsigned values are compared before the cast to int64, which would wrap 2**64 - 1 to -1.
    if a.size and _np.issubdtype(a.dtype, _np.unsignedinteger) and a.max() >= count:
        raise out_of_range
    a = a.astype(_np.int64, copy=False)
    if a.size and (a.min() < -count or a.max() >= count):
        raise out_of_range
    return _np.where(a < 0, a + count, a)


def _vec3(v, what):
    a = _np.asarray(v, dtype=_np.float64).reshape(-1)
    if a.shape != (3,) or not _np.all(_np.isfinite(a)):
        raise ValueError(f"{what} must be 3 finite numbers, got {v!r}")
    return tuple(float(x) for x in a)


def _existing(path):
    path = _os.fspath(path)
    if not _os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    return path


def _threads(threads):
    if threads is None:
        return 0
    threads = int(threads)
    if not 1 <= threads <= _MAX_THREADS:
        raise ValueError(f"threads must be in [1, {_MAX_THREADS}] (or None for all cores), got {threads}")
    return threads


_MAX_THREADS = 1024  # as the CLI and the library (src/core/thread_count.hpp)


def load(path, *, roi=None, fibers=None, threads=None, ignore_trailer=False, data=False):
    """Decodes a .fft or .fftz file into a :class:`Streamlines` (with
    ``data=True``: ``(Streamlines, data)``).

    fibers: None (all), an int, a slice or range, a sequence/array of fiber
        indices (any order; negative indices count from the end, as in
        numpy), or a boolean mask with one value per fiber.
    roi: a region or a list of regions, with MRtrix3 ``tckedit`` semantics:
        a fiber is kept if it has a point inside every include region and
        none inside an exclude region. A region is a :class:`Sphere`,
        :class:`Box` or :class:`Mask` (those three take ``exclude=True``),
        4 numbers (x, y, z, radius: a sphere), 6 numbers (two box corners),
        or an image path (an include mask); a 2-D array is one region per
        row. The block index finds the blocks near the regions: only those
        are decoded to decide, then only the kept fibers.
    threads: decoding threads (None: all cores).
    ignore_trailer: read only the header, LUT and blocks, not the trailer
        after them: salvages a file whose trailer is damaged (which otherwise
        raises a "checksum" FibletError); nothing is then verified.
    data: also return the arrays the file keeps from a .trk or TRX source
        (its DATA chunk, formats/fft-data.md) as a dict of numpy arrays in
        their stored dtypes, each (rows, components): "dps/NAME" one row per
        fiber, "dpv/NAME" one per point, "groups/NAME" (uint32 fiber
        positions), "dpg/GROUP/NAME" (per group); {} for a file made from a
        .tck. The rows follow the returned fibers, also with ``fibers=`` and
        ``roi=``: "dps" rows are those of the returned fibers, in their order
        (repeats repeated), "dpv" rows those of their points, a group lists
        the positions in the returned Streamlines of its fibers that were
        returned, "dpg" arrays are whole. A file whose input was resampled
        (``info(path)["resampled"]``) keeps per-point arrays made for the
        encoded points: float ones float32, interpolated linearly between
        the input points each new point lies between, integer ones the
        nearer input point's in their dtype; the other arrays are the
        source's. Refused (ValueError) with ``ignore_trailer=True``, which
        skips the chunk.

    Raises FileNotFoundError, ValueError/IndexError/TypeError on bad
    arguments, and fiblet.FibletError (with ``.category``, e.g.
    "fft_format", "image_format") on bad files.
    """
    path = _existing(path)
    if data and ignore_trailer:
        raise ValueError("load: data=True reads the DATA chunk of the trailer, which ignore_trailer=True skips")
    regions = _regions(roi)
    begin, end, indices = 0, None, None
    if fibers is not None:
        count = _fiblet.info(path, ignore_trailer)["fibers"]
        if isinstance(fibers, (_numbers.Integral, _np.integer)) and not isinstance(fibers, bool):
            fibers = [fibers]
        chosen = _fiber_indices(fibers, count)
        if isinstance(chosen, slice):
            begin, end = chosen.start, chosen.stop
        else:
            indices = chosen.astype(_np.uint64)
    points, offsets, ids = _fiblet.decode(path, begin, end, indices, regions, _threads(threads), ignore_trailer)
    s = Streamlines(points, offsets, ids)
    if not data:
        return s
    subset = fibers is not None or bool(regions)
    d = _fiblet.data(path, subset)
    if not subset:
        return s, dict(d["fields"])
    return s, _fields_of(d["fields"], s, d["fiber_points"])


def _fields_of(fields, s, fiber_points):
    """The rows of the file's arrays `fields` that belong to the fibers of
    `s` (positions s.fiber_ids in the file, which has fiber_points[f] points
    in fiber f)."""
    ids = s.fiber_ids
    if not _np.array_equal(fiber_points[ids], s.lengths):  # the index and the decoder disagree: never expected
        raise RuntimeError("fiblet: the block index's point counts differ from the decoded fibers'")
    first = _np.zeros(len(fiber_points) + 1, dtype=_np.int64)
    _np.cumsum(fiber_points, out=first[1:])
    # Point k of returned fiber i is row first[ids[i]] + k of a per-point array.
    rows = _np.repeat(first[:-1][ids] - s.offsets[:-1], s.lengths) + _np.arange(s.offsets[-1], dtype=_np.int64)
    out = {}
    for name, a in fields.items():
        scope = name.split("/", 1)[0]
        if scope == "dps":
            out[name] = a[ids]
        elif scope == "dpv":
            out[name] = a[rows]
        elif scope == "groups":
            out[name] = _np.flatnonzero(_np.isin(ids, a[:, 0])).astype(a.dtype).reshape(-1, 1)
        else:  # dpg: one row per group element, not per fiber
            out[name] = a
    return out


def load_array_sequence(path, **options):
    """Decodes a .fft file into a nibabel ArraySequence (no copy of the points)."""
    return load(path, **options).to_array_sequence()


def load_tractogram(path, **options):
    """Decodes a .fft file into a nibabel Tractogram in world millimetres
    (RAS+, ``affine_to_rasmm`` identity), as nibabel gives for a .tck file."""
    from nibabel.streamlines import Tractogram

    return Tractogram(load_array_sequence(path, **options), affine_to_rasmm=_np.eye(4))


def load_sft(path, reference, *, to_space=None, to_origin=None, bbox_valid_check=True, **options):
    """Decodes a .fft file into DIPY's StatefulTractogram, as
    ``dipy.io.streamline.load_tractogram`` loads a .trk or .tck.

    reference: what DIPY accepts as one (a NIfTI path or image, a .trk
        file, a header dict), or "same": the space the file keeps from its
        .trk or TRX source (the PROP keys of formats/fft-data.md: the
        voxel-to-RAS+ affine, dimensions, voxel sizes and order); ValueError
        when the file keeps none (made from a .tck).
    to_space, to_origin: DIPY's ``Space`` and ``Origin`` (or their names
        or values: "rasmm", "vox", "voxmm"; "nifti"/"center",
        "trackvis"/"corner"); default
        ``Space.RASMM``, ``Origin.NIFTI``, as load_tractogram.
    bbox_valid_check: as load_tractogram, raise ValueError when a point
        lies outside the reference's voxel grid
        (``sft.is_bbox_in_vox_valid()`` False); False skips the check.
    options: those of :func:`load` (``fibers=``, ``roi=``, ...). The file's
        per-streamline and per-point arrays (``load(data=True)``, aligned
        with a subset) become ``data_per_streamline`` and ``data_per_point``
        under their names without "dps/" or "dpv/"; groups have no place in
        a StatefulTractogram (``load(data=True)`` gives them). With
        ``ignore_trailer=True`` there are none (and no "same" space).
    Needs DIPY (Debian: python3-dipy)."""
    try:
        from dipy.io.stateful_tractogram import Origin, Space, StatefulTractogram
    except ImportError as e:
        raise ImportError("fiblet.load_sft needs DIPY (pip install dipy, or Debian's python3-dipy)") from e
    from nibabel.streamlines import ArraySequence

    path = _existing(path)
    to_space = Space.RASMM if to_space is None else _dipy_enum(Space, to_space, "to_space")
    to_origin = Origin.NIFTI if to_origin is None else _dipy_enum(Origin, to_origin, "to_origin")
    with_data = not options.get("ignore_trailer", False)
    if isinstance(reference, _os.PathLike):
        reference = _os.fspath(reference)
    if isinstance(reference, str) and reference == "same":
        if not with_data:
            raise ValueError("load_sft: reference='same' reads the space from the file's trailer, "
                             "which ignore_trailer=True skips")
        reference = _trk_header(path, _fiblet.data(path, False)["space"])
    if with_data:
        s, data = load(path, data=True, **options)
    else:
        s, data = load(path, **options), {}
    seq = s.to_array_sequence()
    per_streamline = {name[4:]: a for name, a in data.items() if name.startswith("dps/")}
    per_point = {}
    for name, a in data.items():
        if name.startswith("dpv/"):
            values = ArraySequence()
            values._data, values._offsets, values._lengths = a, seq._offsets, seq._lengths
            per_point[name[4:]] = values
    sft = StatefulTractogram(seq, reference, Space.RASMM, origin=Origin.NIFTI,
                             data_per_point=per_point, data_per_streamline=per_streamline)
    sft.to_space(to_space)
    sft.to_origin(to_origin)
    if bbox_valid_check and not sft.is_bbox_in_vox_valid():
        raise ValueError(f"load_sft: {path}: the bounding box is not valid in voxel space of the reference "
                         f"(points outside its grid), as dipy.io.streamline.load_tractogram refuses; pass "
                         f"bbox_valid_check=False, then remove_invalid_streamlines() to discard them")
    return sft


def _dipy_enum(kind, value, what):
    """A DIPY Space or Origin from itself, its name ("VOX", "trackvis") or its value ("vox", "corner")."""
    if isinstance(value, kind):
        return value
    if isinstance(value, str):
        if value.upper() in kind.__members__:
            return kind[value.upper()]
        if value in {m.value for m in kind}:
            return kind(value)
    raise ValueError(f"load_sft: {what} must be a dipy {kind.__name__} or one of "
                     f"{', '.join(sorted({m.name.lower() for m in kind} | {m.value for m in kind}))}; got {value!r}")


def _trk_header(path, space):
    """The space a .fft keeps, as the TrackVis header dict DIPY takes as a reference."""
    if space is None:
        raise ValueError(f"load_sft: {path} keeps no reference space (it was made from a .tck, or points): "
                         f"reference='same' needs a .fft made from a .trk or TRX; pass a reference image")
    return {"magic_number": b"TRACK", "voxel_to_rasmm": space["voxel_to_rasmm"].astype(_np.float32),
            "dimensions": space["dimensions"].astype(_np.int16), "voxel_sizes": space["voxel_sizes"].astype(_np.float32),
            "voxel_order": space["voxel_order"]}


def _flatten(streamlines):
    """(points float32 (N,3), offsets int64 (F+1)) from the accepted inputs."""
    if isinstance(streamlines, bytes):  # (str and path objects name a tractogram: save() compresses it)
        raise TypeError(f"save(path, streamlines): streamlines must be points or a file name (str, os.PathLike), "
                        f"not bytes ({streamlines!r})")
    if isinstance(streamlines, Streamlines):
        return streamlines.points, streamlines.offsets
    if isinstance(streamlines, tuple) and len(streamlines) == 2 and all(
            isinstance(a, _np.ndarray) for a in streamlines):
        return streamlines
    try:  # nibabel objects, imported only when nibabel is there
        from nibabel.streamlines.array_sequence import ArraySequence
        from nibabel.streamlines.tractogram import Tractogram
        from nibabel.streamlines.tractogram_file import TractogramFile
    except ImportError:
        ArraySequence = Tractogram = TractogramFile = ()
    if isinstance(streamlines, TractogramFile):
        streamlines = streamlines.tractogram
    if isinstance(streamlines, Tractogram):
        affine = streamlines.affine_to_rasmm
        if affine is not None and not _np.allclose(affine, _np.eye(4)):
            streamlines = streamlines.copy().to_world()
        streamlines = streamlines.streamlines
    if isinstance(streamlines, ArraySequence):
        lengths = _np.asarray(streamlines._lengths, dtype=_np.int64)
        points = streamlines.get_data() if len(lengths) else _np.zeros((0, 3), _np.float32)
    else:
        try:
            items = list(streamlines)
        except TypeError:
            raise TypeError(f"streamlines must be a fiblet.Streamlines, a nibabel ArraySequence or Tractogram, "
                            f"a list of (n, 3) arrays or (points, offsets); got {type(streamlines).__name__}") from None
        fibers = []
        for i, f in enumerate(items):
            try:
                fibers.append(_np.asarray(f, dtype=_np.float32))
            except (TypeError, ValueError) as e:
                raise TypeError(f"streamline {i} is not an (n, 3) array of numbers ({e})") from None
            if fibers[-1].ndim != 2 or fibers[-1].shape[1] != 3:
                raise ValueError(f"streamline {i} has shape {fibers[-1].shape}, expected (n, 3)")
        lengths = _np.array([len(f) for f in fibers], dtype=_np.int64)
        points = _np.concatenate(fibers) if fibers else _np.zeros((0, 3), _np.float32)
    offsets = _np.zeros(len(lengths) + 1, dtype=_np.int64)
    _np.cumsum(lengths, out=offsets[1:])
    return points, offsets


def read_streamlines(path):
    """Reads a .tck, .trk or TRX file through the readers ``fiblet compress``
    uses, or decodes a .fft/.fftz; returns ``(Streamlines, data)``: points in
    world RAS+ mm (for a .trk exactly as nibabel's ``load(path).streamlines``),
    and a dict of the per-streamline ("dps/NAME"), per-point ("dpv/NAME") and
    group arrays, each (rows, components). A .fft (recognised by its content)
    gives ``load(path, data=True)``: the decoded points and the arrays it
    keeps from its source (resampled per-point arrays as :func:`load` says)."""
    path = _existing(path)
    if _fiblet.container(path) != "other":
        return load(path, data=True)
    r = _fiblet.read_streamlines(path)
    return Streamlines(r["points"], r["offsets"]), r["data"]


# What save() writes, by the output's extension (any case).
_COMPRESSED = (".fft", ".fftz")         # compressed (.fftz: the seekable zstd container, `fiblet compress --zstd`)
_STREAMLINE_FILES = (".tck", ".trk", ".trx")  # written by the writers of `fiblet decompress`
_SAVE_EXTENSIONS = _COMPRESSED + _STREAMLINE_FILES


def _output_kind(path):
    """The extension of `path` that save() writes, lower-cased; ValueError for any other."""
    ext = _os.path.splitext(path)[1].lower()
    if ext not in _SAVE_EXTENSIONS:
        raise ValueError(f"save: cannot write {path!r}: the file name must end in one of "
                         f"{', '.join(_SAVE_EXTENSIONS)} (the format is chosen by the extension)")
    return ext


def _memory_budget(max_memory):
    """CompressOptions::max_memory: 0 (the library's default) for None."""
    if max_memory is None:
        return 0
    if isinstance(max_memory, bool) or not isinstance(max_memory, int) or not 0 < max_memory < 2**63:
        raise ValueError(f"max_memory must be a positive number of bytes, got {max_memory!r}")
    return max_memory


def save(path, streamlines, step=None, *, overwrite=False, threads=None, max_memory=None, fine_index=False):
    """Writes streamlines to ``path`` in the format its extension names.

    - ``.fft``: compressed, as ``fiblet compress``; ``.fftz``: compressed
      into the seekable zstd container, as ``fiblet compress --zstd``.
      Returns the compression report (the keys of ``fiblet compress
      --json``: ratio, max_error_um, ...).
    - ``.tck``, ``.trk``, ``.trx``: the points as they are, written by the
      writers of ``fiblet decompress`` (a .trk or .trx of points gets the
      identity space: RAS+, 1 mm voxels). Returns ``{"output", "fibers",
      "points", "output_bytes"}``.
    - Any other extension raises ValueError and writes nothing.

    streamlines: a :class:`Streamlines`, a nibabel ArraySequence, Tractogram or
        loaded tractogram file, a list of (n, 3) arrays, or (points, offsets).
        Coordinates are world millimetres. Or the path of a .tck, .trk or
        TRX file, read by the same readers as ``fiblet compress`` (its
        per-streamline and per-point data kept in a .fft, .fftz, .trk or
        .trx; a .tck holds points only, and a warning says what was left out).
    step: the fixed step in mm, for .fft/.fftz (default: measured; input with
        variable spacing is resampled to it); refused for other outputs.
    overwrite: replace an existing file (else FileExistsError).
    threads: compression threads (None: all cores).
    max_memory: bytes compression may give the per-point arrays of resampled
        streamlines (None: half the memory the process may use, as the CLI's
        --max-memory); beyond it nothing is
        written and an error says how much was needed.
    fine_index: for .fft/.fftz, write the finer block index (BIDX version 4,
        a box per block, as ``fiblet compress --fine-index``): fewer candidate
        blocks for ``roi=`` queries, but about 5x slower to load (32 ms
        against 6 ms on a 46 M-point file); worth it for files queried many
        times in one session. Refused for other outputs.

    Points for a .fft/.fftz go through a temporary .tck file (in the default
    temporary directory, see ``tempfile``), which is removed afterwards.
    Every output is written atomically: complete, or not at all.
    """
    if not isinstance(path, (str, _os.PathLike)):
        raise TypeError(f"save(path, streamlines): path must be a file name, got {type(path).__name__}")
    path = _os.fspath(path)
    ext = _output_kind(path)
    if step is not None and ext not in _COMPRESSED:
        raise ValueError(f"save: step= resamples for compression (.fft, .fftz); {path!r} gets the points as they are")
    if fine_index and ext not in _COMPRESSED:
        raise ValueError(f"save: fine_index= is the block index of a .fft/.fftz; {path!r} has none")
    if _os.path.exists(path) and not overwrite:
        raise FileExistsError(f"{path} exists (pass overwrite=True)")
    zstd, nthreads = ext == ".fftz", _threads(threads)
    if isinstance(streamlines, (str, _os.PathLike)):
        source = _existing(streamlines)
        if ext in _COMPRESSED:
            return _fiblet.compress(source, path, None if step is None else float(step), bool(overwrite),
                                    nthreads, zstd, _memory_budget(max_memory), bool(fine_index))
        written = _fiblet.convert(source, path, bool(overwrite))
        if written.pop("fields_dropped"):
            import warnings
            warnings.warn(f"save: the data arrays of {source} are not in {path}: a .tck holds points only "
                          f"(write a .trk or .trx to keep them)", stacklevel=2)
        return _written(path, written)
    points, offsets = _flatten(streamlines)
    points = _np.ascontiguousarray(points, dtype=_np.float32)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must be (N, 3), got {points.shape}")
    if not _np.all(_np.isfinite(points)):
        raise ValueError("points must be finite (no NaN or Inf)")
    offsets = _np.ascontiguousarray(offsets, dtype=_np.int64)
    if ext not in _COMPRESSED:
        _fiblet.write_streamlines(path, points, offsets, [], bool(overwrite))
        return _written(path, {"fibers": len(offsets) - 1, "points": len(points)})
    properties = [] if step is None else [("step_size", repr(float(step)))]
    with _tempfile.TemporaryDirectory(prefix="fiblet-save-") as tmp:
        tck = _os.path.join(tmp, "streamlines.tck")
        _fiblet.write_streamlines(tck, points, offsets, properties, False)
        report = _fiblet.compress(tck, path, None if step is None else float(step), bool(overwrite),
                                  nthreads, zstd, _memory_budget(max_memory), bool(fine_index))
    report["input"] = None  # the temporary .tck is gone
    return report


def _written(path, counts):
    """save()'s report for a .tck, .trk or .trx."""
    return {"output": path, "fibers": int(counts["fibers"]), "points": int(counts["points"]),
            "output_bytes": _os.path.getsize(path)}


def stats(fft, reference):
    """Measures a .fft file against the .tck it was made from; returns the
    keys of ``fiblet stats --json`` (error in µm: max_um, mean_um, p99_um, ...);
    ``geometry`` holds the symmetric metrics against the reference polylines:
    decoded_to_input and input_to_decoded distances, hausdorff_um, endpoint
    displacement and length_change (µm and %)."""
    return _fiblet.stats(_existing(fft), _existing(reference))


def info(path, *, ignore_trailer=False):
    """The header of a .fft file as a dict (fibers, points, step_mm,
    max_error_um recorded by the encoder, source .tck properties, ...)."""
    return _fiblet.info(_existing(path), ignore_trailer)


# nibabel opens .fft/.fftz files through fiblet (nibabel_format.py), when
# nibabel is installed; fiblet does not need it.
try:
    from . import nibabel_format as _nibabel_format
except ImportError:
    pass
else:
    _nibabel_format.register()
