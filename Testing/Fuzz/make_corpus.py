#!/usr/bin/env python3
"""Writes the seed corpus of the fuzz targets (run once; the files are
committed). particle_text seeds carry one leading flag byte (bit 0 lenient,
bit 1 double precision, bit 7 two threads); slice_stack seeds one byte that
picks the extension (0 png, 1 tif, 2 bmp, 3 jpg, 4 dcm)."""
import gzip, os, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))

texts = {
    # the thesis format: x y z r g b reflectivity refraction
    "thesis": "1.5 2.5 3.5 255 128 0 0.25 1.33\n-1 -2 -3 0 0 0 1 0\n0 0 0 10 20 30 0 1.5\n",
    "header_reordered": "# r g b x y z reflectivity refraction id\n255 128 0 1.5 2.5 3.5 0.25 1.33 7\n",
    "csv_header": "x,y,z,intensity\n1,2,3,0.5\n4,5,6,0.25\n",
    "four_columns": "1 2 3 0.5\r\n4 5 6 0.7\r\n",
    "six_columns": "1 2 3 0 0 0\n4 5 6 255 255 255\n",
    "exponents": "1e3 -2.5E-2 +3\n0x1 inf nan\n",
    "comments_blank": "# comment\n\n   \n1 2 3 # trailing\n",
    "utm": "637012.24 849028.31 431.66\n",
    # every malformed case of the reader tests (Testing/Python, IO/Particles/Testing/Cxx)
    "bad_short_line": "1 2 3\n4 5\n",
    "bad_long_line": "1 2 3\n4 5 6 7\n",
    "bad_word": "1 2 3\n4 abc 6\n",
    "bad_suffix": "1 2 3\n4 5 6x\n",
    "bad_nan": "1 2 3\n4 nan 6\n",
    "bad_inf": "1 2 3\n4 5 -inf\n",
    "bad_empty_field": "1 2 3\n4,,6\n",
    "bad_colour": "1 2 3 0 0 0\n1 2 3 0 256 0\n",
    "bad_reflectivity": "1 2 3 0 0 0 1.5 0\n",
    "bad_count": "1 2\n",
    "not_header": "# x y q\n1 2 3\n",
    "bad_header_twice": "# x y z x\n1 2 3 4\n",
    "bad_header_rgb": "# x y z r g\n1 2 3 4 5\n",
    "only_comment": "# only a comment\n\n",
    "empty": "",
    "nul_bytes": "1 2 3\n\0\0\0\n",
    "plus_minus": "+-1 2 3\n",
}
for name, text in texts.items():
    for flag, suffix in ((0, ""), (1, "_lenient")):
        for d, path in (("particle_text", bytes([flag]) + text.encode()),
                        ("particle_header", text.encode())):
            if d == "particle_header" and flag:
                continue
            with open(os.path.join(here, "corpus", d, name + suffix), "wb") as f:
                f.write(path)
with open(os.path.join(root, "Data/Particles/lidar_simple.particles"), "rb") as f:
    lidar = f.read()
first = b"".join(lidar.splitlines(True)[:40])
open(os.path.join(here, "corpus/particle_text/lidar_head"), "wb").write(b"\2" + first)
open(os.path.join(here, "corpus/particle_header/lidar_head"), "wb").write(first)
blob = gzip.compress(texts["thesis"].encode(), mtime=0)
open(os.path.join(here, "corpus/particle_text/thesis_gz"), "wb").write(b"\0" + blob)
open(os.path.join(here, "corpus/particle_text/truncated_gz"), "wb").write(b"\0" + blob[: len(blob) // 2])

with tempfile.TemporaryDirectory() as tmp:
    for i, ext in enumerate(("png", "tif", "bmp", "jpg", "dcm")):
        if ext == "dcm":
            src = os.path.join(root, "Data/DICOM/CT5N/2062.dcm")
        else:
            src = os.path.join(tmp, "s." + ext)
            subprocess.run(["oiiotool", "--pattern", "checker:width=2:height=2", "4x3", "1",
                            "-d", "uint8", "-o", src], check=True)
        data = open(src, "rb").read()
        open(os.path.join(here, "corpus/slice_stack", "seed_" + ext), "wb").write(bytes([i]) + data)
        # the reader tests' corrupt slice: a PNG signature and garbage
    open(os.path.join(here, "corpus/slice_stack/corrupt_png"), "wb").write(b"\0\x89PNG\r\n\x1a\n garbage")

# DICOM in the other encodings and shapes the structure check walks (written
# by pydicom from the bundled slice): implicit VR little endian, explicit VR
# big endian, and nested undefined-length sequences with an undefined-length
# UN and encapsulated (JPEG-labelled) pixel data.
import pydicom
from pydicom.dataset import Dataset
from pydicom.encaps import encapsulate
from pydicom.sequence import Sequence
from pydicom.uid import ImplicitVRLittleEndian, ExplicitVRBigEndian, JPEGBaseline8Bit


def dicom_seed(name, syntax, edit=None):
    ds = pydicom.dcmread(os.path.join(root, "Data/DICOM/CT5N/2062.dcm"))
    ds.file_meta.TransferSyntaxUID = syntax
    ds.is_implicit_VR = syntax == ImplicitVRLittleEndian
    ds.is_little_endian = syntax != ExplicitVRBigEndian
    if edit:
        edit(ds)
    path = os.path.join(here, "corpus/slice_stack", name)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "s.dcm")
        ds.save_as(out, write_like_original=False)
        data = open(out, "rb").read()
    open(path, "wb").write(b"\4" + data)


def nested(ds):
    inner = Dataset()
    inner.CodeValue = "T-D1100"
    inner.CodingSchemeDesignator = "SRT"
    item = Dataset()
    item.ReferencedSOPInstanceUID = ds.SOPInstanceUID
    item.ConceptNameCodeSequence = Sequence([inner])
    ds.ReferencedImageSequence = Sequence([item, Dataset()])
    ds.ReferencedImageSequence.is_undefined_length = True
    for i in ds.ReferencedImageSequence:
        i.is_undefined_length_sequence_item = True
    # an undefined-length UN: an implicit VR item (pydicom adds the
    # sequence delimiter)
    ds.add_new(0x00091010, "UN", b"\xfe\xff\x00\xe0\xff\xff\xff\xff\x09\x00\x01\x10\x02\x00\x00\x00ab"
               b"\xfe\xff\x0d\xe0\x00\x00\x00\x00")
    ds[0x00091010].is_undefined_length = True
    ds.PixelData = encapsulate([b"\xff\xd8\xff\xd9"])
    ds[0x7FE00010].VR = "OB"
    ds[0x7FE00010].is_undefined_length = True


dicom_seed("seed_dcm_implicit", ImplicitVRLittleEndian)
dicom_seed("seed_dcm_bigendian", ExplicitVRBigEndian)
dicom_seed("seed_dcm_sequences", JPEGBaseline8Bit, nested)
