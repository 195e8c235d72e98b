"""An X3P file's MD5 checksums are checked before its heights are used (issue 35's audit).

Requirement: ISO 25178-72 makes ``md5checksum.hex`` (the MD5 of ``main.xml``) part of the container, and
``main.xml`` states the MD5 of the point data (``MD5ChecksumPointData``).  A file whose bytes do not match
what it states is corrupted: refused naming the file, the stated and the actual checksum (exit 2 from the
command line, nothing written).  A file without the checksum entry is read as it is.
"""
import hashlib
import os
import zipfile

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.errors import GeometryError
from ngcontact.geometry import random_surface
from ngcontact.geometry.topography import Reading, read_measured
from ngcontact.geometry.x3p import write_x3p

NEEDS = "reading measured topographies needs the optional extra ngcontact[topography] (SurfaceTopography)"
P, N = 1e-4, 16
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.fixture
def scan(tmp_path):
    pytest.importorskip("SurfaceTopography", reason=NEEDS)
    z = random_surface.self_affine(grid=N, period=P, hurst=0.8, rms_slope=0.05, seed=1)
    write_x3p(tmp_path / "scan.x3p", z, (P / N, P / N))
    return tmp_path / "scan.x3p"


def rewritten(src, dst, edits: dict, drop: tuple = ()):
    """A copy of the zip ``src`` at ``dst`` with members ``edits[name](bytes)`` changed and ``drop`` left out
    (the zip's own CRCs consistent: only the X3P checksums can tell)."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            if info.filename in drop:
                continue
            data = zin.read(info.filename)
            zout.writestr(info, edits.get(info.filename, lambda b: b)(data))
    return dst


def md5(path, member: str) -> str:
    with zipfile.ZipFile(path) as z:
        return hashlib.md5(z.read(member)).hexdigest()


def test_a_changed_main_xml_is_refused_with_both_checksums(scan):
    bad = rewritten(scan, scan.with_name("bad.x3p"),
                    {"main.xml": lambda b: b.replace(b"<Comment>height map", b"<Comment>edited map")})
    stated, actual = md5(scan, "main.xml"), md5(bad, "main.xml")
    assert stated != actual
    with pytest.raises(GeometryError) as err:
        read_measured(bad, Reading(periodic=True))
    assert str(err.value) == (f"geometry.file = {str(bad)!r}: is corrupted: the MD5 of its main.xml is {actual}, "
                              f"but its md5checksum.hex states {stated}; read the scan from the instrument again")


def test_changed_heights_are_refused_by_the_point_data_checksum(scan):
    def flip(data: bytes) -> bytes:
        h = np.frombuffer(data, "<f8").copy()
        h[3] += 1e-9
        return h.tobytes()
    bad = rewritten(scan, scan.with_name("bad.x3p"), {"bindata/data.bin": flip})
    with pytest.raises(GeometryError, match=f"is corrupted: the MD5 of its bindata/data.bin is "
                                            f"{md5(bad, 'bindata/data.bin')}, but its main.xml states "
                                            f"{md5(scan, 'bindata/data.bin')}; "):
        read_measured(bad, Reading(periodic=True))


def test_a_checksum_file_that_holds_no_checksum_is_refused(scan):
    bad = rewritten(scan, scan.with_name("bad.x3p"), {"md5checksum.hex": lambda b: b"not a checksum\n"})
    with pytest.raises(GeometryError, match=r"is corrupted: its md5checksum.hex holds 'not a checksum', not an MD5 "
                                            r"checksum \(32 hexadecimal digits\)"):
        read_measured(bad, Reading(periodic=True))


def test_a_file_without_the_checksum_entry_is_read_as_it_is(scan):
    bare = rewritten(scan, scan.with_name("bare.x3p"), {}, drop=("md5checksum.hex",))
    np.testing.assert_array_equal(read_measured(bare, Reading(periodic=True)).heights,
                                  read_measured(scan, Reading(periodic=True)).heights)


def test_an_uppercase_checksum_naming_its_member_is_accepted(scan):
    """SurfaceTopography's writer states upper-case digits; the name after ``*`` says which member is meant."""
    upper = rewritten(scan, scan.with_name("upper.x3p"), {"md5checksum.hex": lambda b: b.upper().replace(
        b"*MAIN.XML", b"*main.xml")})
    read_measured(upper, Reading(periodic=True))


def test_the_command_line_refuses_a_corrupted_copy_of_the_shipped_scan(tmp_path, capsys):
    """``ngcontact run`` on the shipped measured_scan.toml with a corrupted ground_scan.x3p: exit 2, one line,
    no output directory."""
    pytest.importorskip("SurfaceTopography", reason=NEEDS)
    cells = os.path.join(ROOT, "geometries", "cells")
    (tmp_path / "data").mkdir()
    shipped = os.path.join(cells, "data", "ground_scan.x3p")
    bad = rewritten(shipped, tmp_path / "data" / "ground_scan.x3p",
                    {"main.xml": lambda b: b.replace(b"</Comment>", b" (edited)</Comment>", 1)})
    with open(os.path.join(cells, "measured_scan.toml")) as f:
        (tmp_path / "scene.toml").write_text(f.read())
    out = tmp_path / "out"
    assert cli.main(["run", str(tmp_path / "scene.toml"), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is corrupted: the MD5 of its main.xml is " + md5(bad, "main.xml") in err \
        and "its md5checksum.hex states " + md5(shipped, "main.xml") in err and "ground_scan.x3p" in err, err
    assert not out.exists()
