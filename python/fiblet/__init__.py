"""fiblet: compressed tractograms (.fft) decoded straight into numpy.

    import fiblet
    s = fiblet.load("sub-01_tracks.fft")        # all fibers
    s.points        # (N, 3) float32, world millimetres (RAS+, as in .tck)
    s.offsets       # (F + 1,) int64: fiber i is points[offsets[i]:offsets[i + 1]]
    s.lengths       # (F,) int64 points per fiber
    s[i]            # the (n_i, 3) points of fiber i (a view)

    tractogram = fiblet.load_tractogram("tracks.fft")   # nibabel Tractogram
    fiblet.save("out.fft", tractogram.streamlines)      # from nibabel, lists, ...
    fiblet.stats("out.fft", "in.tck")                   # measured error

The decoded points are handed to numpy without a copy: the arrays own the
decoder's buffers.
"""

import os
import tempfile
from dataclasses import dataclass

import numpy as np

from . import _fiblet
from ._fiblet import FibletError

__version__ = _fiblet.version
__all__ = [
    "Streamlines", "Sphere", "Box", "FibletError",
    "load", "load_array_sequence", "load_tractogram", "read_streamlines", "save", "stats", "info",
]


class Streamlines:
    """Fibers in the TRX layout: one (N, 3) float32 point array and offsets.

    ``fiber_ids`` gives, for each fiber, its index in the file it came from
    (useful after a ``fibers=`` or ``roi=`` selection).
    """

    __slots__ = ("points", "offsets", "fiber_ids", "_lengths")

    def __init__(self, points, offsets, fiber_ids=None):
        self.points = points
        self.offsets = offsets
        self.fiber_ids = np.arange(len(offsets) - 1) if fiber_ids is None else fiber_ids
        self._lengths = None

    @property
    def lengths(self):
        """Points per fiber, (F,) int64."""
        if self._lengths is None:
            self._lengths = np.diff(self.offsets)
        return self._lengths

    def __len__(self):
        return len(self.offsets) - 1

    def __getitem__(self, i):
        n = len(self)
        if not -n <= i < n:
            raise IndexError(f"fiber {i} out of range ({n} fibers)")
        i %= n
        return self.points[self.offsets[i]:self.offsets[i + 1]]

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


@dataclass(frozen=True)
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


@dataclass(frozen=True)
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


def _vec3(v, what):
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{what} must be 3 finite numbers, got {v!r}")
    return tuple(float(x) for x in a)


def _existing(path):
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    return path


def _threads(threads):
    if threads is None:
        return 0
    threads = int(threads)
    if threads < 1:
        raise ValueError(f"threads must be >= 1 (or None for all cores), got {threads}")
    return threads


def load(path, *, roi=None, fibers=None, threads=None, ignore_trailer=False):
    """Decodes a .fft file into a :class:`Streamlines`.

    fibers: None (all), a slice or range with step 1 (decoded as one range),
        an int, or a sequence/array of fiber indices (any order; negative
        indices count from the end, as in numpy).
    roi: a :class:`Sphere` or :class:`Box`, or a list of them, with MRtrix3
        ``tckedit`` semantics: a fiber is kept if it has a point inside every
        include region and none inside an exclude region.
    threads: decoding threads (None: all cores).
    ignore_trailer: read only the header, LUT and blocks, not the trailer
        after them: salvages a file whose trailer is damaged (which otherwise
        raises a "checksum" FibletError); nothing is then verified.

    Raises FileNotFoundError, ValueError/IndexError on bad arguments, and
    fiblet.FibletError (with ``.category``, e.g. "fft_format") on bad files.
    """
    path = _existing(path)
    regions = [] if roi is None else [r._spec() for r in (roi if isinstance(roi, (list, tuple)) else [roi])]
    begin, end, indices = 0, None, None
    if fibers is not None:
        count = _fiblet.info(path, ignore_trailer)["fibers"]
        if isinstance(fibers, (slice, range)):
            if fibers.step not in (None, 1):
                indices = np.arange(count)[slice(fibers.start, fibers.stop, fibers.step)]
            else:
                begin, end, _ = slice(fibers.start, fibers.stop).indices(count)
                end = max(begin, end)
        else:
            indices = np.asarray(fibers)
            if indices.ndim == 0:
                indices = indices.reshape(1)
            if indices.size and not np.issubdtype(indices.dtype, np.integer):
                raise TypeError(f"fibers must be integers, a slice or a range, got {indices.dtype}")
            indices = indices.astype(np.int64, copy=False)
            if indices.size and (indices.min() < -count or indices.max() >= count):
                raise IndexError(f"fiber index out of range ({count} fibers)")
            indices = np.where(indices < 0, indices + count, indices)
        if indices is not None:
            indices = indices.astype(np.uint64)
    points, offsets, ids = _fiblet.decode(path, begin, end, indices, regions, _threads(threads), ignore_trailer)
    return Streamlines(points, offsets, ids)


def load_array_sequence(path, **options):
    """Decodes a .fft file into a nibabel ArraySequence (no copy of the points)."""
    return load(path, **options).to_array_sequence()


def load_tractogram(path, **options):
    """Decodes a .fft file into a nibabel Tractogram in world millimetres
    (RAS+, ``affine_to_rasmm`` identity), as nibabel gives for a .tck file."""
    from nibabel.streamlines import Tractogram

    return Tractogram(load_array_sequence(path, **options), affine_to_rasmm=np.eye(4))


def _flatten(streamlines):
    """(points float32 (N,3), offsets int64 (F+1)) from the accepted inputs."""
    if isinstance(streamlines, Streamlines):
        return streamlines.points, streamlines.offsets
    if isinstance(streamlines, tuple) and len(streamlines) == 2 and all(
            isinstance(a, np.ndarray) for a in streamlines):
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
        if affine is not None and not np.allclose(affine, np.eye(4)):
            streamlines = streamlines.copy().to_world()
        streamlines = streamlines.streamlines
    if isinstance(streamlines, ArraySequence):
        lengths = np.asarray(streamlines._lengths, dtype=np.int64)
        points = streamlines.get_data() if len(lengths) else np.zeros((0, 3), np.float32)
    else:
        fibers = [np.asarray(f, dtype=np.float32) for f in streamlines]
        for i, f in enumerate(fibers):
            if f.ndim != 2 or f.shape[1] != 3:
                raise ValueError(f"streamline {i} has shape {f.shape}, expected (n, 3)")
        lengths = np.array([len(f) for f in fibers], dtype=np.int64)
        points = np.concatenate(fibers) if fibers else np.zeros((0, 3), np.float32)
    offsets = np.zeros(len(lengths) + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    return points, offsets


def read_streamlines(path):
    """Reads a .tck, .trk or TRX file through the readers ``fiblet compress``
    uses; returns ``(Streamlines, data)``: points in world RAS+ mm (for a
    .trk exactly as nibabel's ``load(path).streamlines``), and a dict of the
    per-streamline ("dps/NAME"), per-point ("dpv/NAME") and group arrays,
    each (rows, components)."""
    r = _fiblet.read_streamlines(_existing(path))
    return Streamlines(r["points"], r["offsets"]), r["data"]


def save(path, streamlines, step=None, *, overwrite=False, threads=None):
    """Compresses streamlines into a .fft file; returns the compression report
    (the keys of ``fiblet compress --json``: ratio, max_error_um, ...).

    streamlines: a :class:`Streamlines`, a nibabel ArraySequence, Tractogram or
        loaded tractogram file, a list of (n, 3) arrays, or (points, offsets).
        Coordinates are world millimetres. Or the path of a .tck, .trk or
        TRX file, compressed directly by the same readers as
        ``fiblet compress`` (its per-streamline and per-point data kept).
    step: the fixed step in mm (default: measured; input with variable
        spacing is resampled to it).

    The points go through a temporary .tck file (in the default temporary
    directory, see ``tempfile``), which is removed afterwards; the .fft is
    written atomically.
    """
    path = os.fspath(path)
    if os.path.exists(path) and not overwrite:
        raise FileExistsError(f"{path} exists (pass overwrite=True)")
    if isinstance(streamlines, (str, os.PathLike)):
        return _fiblet.compress(_existing(streamlines), path, None if step is None else float(step),
                                bool(overwrite), _threads(threads))
    points, offsets = _flatten(streamlines)
    points = np.ascontiguousarray(points, dtype=np.float32)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must be (N, 3), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise ValueError("points must be finite (no NaN or Inf)")
    properties = [] if step is None else [("step_size", repr(float(step)))]
    with tempfile.TemporaryDirectory(prefix="fiblet-save-") as tmp:
        tck = os.path.join(tmp, "streamlines.tck")
        _fiblet.write_tck(tck, points, np.ascontiguousarray(offsets, dtype=np.int64), properties, False)
        report = _fiblet.compress(tck, path, None if step is None else float(step), bool(overwrite),
                                  _threads(threads))
    report["input"] = None  # the temporary .tck is gone
    return report


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
