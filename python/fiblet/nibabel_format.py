"""A nibabel streamlines format for .fft/.fftz files, registered in
``nibabel.streamlines.FORMATS`` when ``fiblet`` is imported (if nibabel
imports), so that ``nib.streamlines.load("x.fft")``,
``nib.streamlines.save(tractogram, "x.fft")`` and
``nib.streamlines.detect_format("x.fft")`` go through fiblet.

DIPY 1.6's ``load_tractogram``/``save_tractogram`` accept a fixed list of
extensions and do not consult nibabel's FORMATS: ``fiblet.load_sft`` is the
DIPY route.
"""
import os
import tempfile

import numpy as np
from nibabel.streamlines.array_sequence import ArraySequence
from nibabel.streamlines.tractogram import Tractogram
from nibabel.streamlines.tractogram_file import TractogramFile
from nibabel.streamlines.trk import TrkFile

EXTENSIONS = (".fft", ".fftz")


class FftFile(TractogramFile):
    """A .fft/.fftz tractogram: points in world RAS+ mm (``affine_to_rasmm``
    identity); ``data_per_streamline``/``data_per_point`` are the file's
    ``dps/NAME``/``dpv/NAME`` arrays (its DATA chunk, kept from a .trk or
    TRX source) under ``NAME``. Groups and per-group arrays have no place in
    a nibabel Tractogram: ``fiblet.load(path, data=True)`` gives them.

    ``save`` compresses through ``fiblet.save``; a tractogram with data goes
    through a temporary .trk written by nibabel, so its values are stored as
    the .trk holds them (float32) and the file keeps that .trk's space
    (identity, 1 mm voxels) as its reference. The header is ``{}``.
    """

    SUPPORTS_DATA_PER_POINT = True
    SUPPORTS_DATA_PER_STREAMLINE = True

    @classmethod
    def is_correct_format(cls, fileobj):
        """True for the path of an existing .fft or .fftz file (by its
        content, whatever its name); False for anything else."""
        from . import _fiblet

        if not isinstance(fileobj, (str, os.PathLike)) or not os.path.isfile(fileobj):
            return False
        return _fiblet.container(os.fspath(fileobj)) in ("fft", "fftz")

    @classmethod
    def create_empty_header(cls):
        return {}

    @classmethod
    def load(cls, fileobj, lazy_load=False):
        """Decodes the file (``lazy_load`` is accepted and ignored: the
        points are decoded at once)."""
        import fiblet

        if not isinstance(fileobj, (str, os.PathLike)):
            raise TypeError(f"fiblet reads .fft files by path, not from {type(fileobj).__name__}")
        s, data = fiblet.load(fileobj, data=True)
        streamlines = s.to_array_sequence()
        per_streamline, per_point = {}, {}
        for name, values in data.items():
            scope, short = name.split("/", 1)
            if scope == "dps":
                per_streamline[short] = values
            elif scope == "dpv":
                seq = ArraySequence()
                seq._data, seq._offsets, seq._lengths = values, streamlines._offsets, streamlines._lengths
                per_point[short] = seq
        tractogram = Tractogram(streamlines, data_per_streamline=per_streamline, data_per_point=per_point,
                                affine_to_rasmm=np.eye(4))
        return cls(tractogram)

    def save(self, fileobj):
        """Compresses the tractogram (in world RAS+ mm) into ``fileobj``, a
        .fft or .fftz path (replaced if it exists, as nibabel's formats do)."""
        import fiblet

        if not isinstance(fileobj, (str, os.PathLike)):
            raise TypeError(f"fiblet writes .fft files by path, not to {type(fileobj).__name__}")
        path = os.fspath(fileobj)
        if os.path.splitext(path)[1].lower() not in EXTENSIONS:
            raise ValueError(f"{path!r}: a fiblet file's name ends in .fft or .fftz")
        tractogram = self.tractogram.to_world(lazy=True)
        if not len(tractogram.data_per_streamline) and not len(tractogram.data_per_point):
            fiblet.save(path, tractogram.streamlines, overwrite=True)
            return
        with tempfile.TemporaryDirectory(prefix="fiblet-nibabel-") as tmp:
            trk = os.path.join(tmp, "tractogram.trk")
            TrkFile(tractogram).save(trk)
            fiblet.save(path, trk, overwrite=True)


def register():
    """Adds :class:`FftFile` to nibabel's FORMATS for .fft and .fftz."""
    from nibabel.streamlines import FORMATS

    for ext in EXTENSIONS:
        FORMATS[ext] = FftFile
