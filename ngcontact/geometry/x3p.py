"""A minimal X3P file (ISO 25178-72 / ISO 5436-2): a height map written as an instrument would write its scan,
and the check of a file's checksums before its heights are read.

:func:`write_x3p` is used by the tests of measured topographies (:mod:`ngcontact.geometry.topography`) and
by the script that writes the shipped scan, so that both read the heights back through SurfaceTopography's
reader, the route of a real instrument's file.  :func:`check_checksums` is run on every X3P file a scene
reads (SurfaceTopography does not check them).

The container is a zip of ``main.xml`` (the axes: ``CX``, ``CY`` incremental with their spacing in metres,
``CZ`` absolute heights in metres; the matrix dimensions and the link to the data) and the binary heights
``bindata/data.bin``: little-endian doubles, ``x`` running fastest (rows of constant ``y``), and the MD5
checksums the standard asks for.
"""
from __future__ import annotations

import hashlib
import re
import zipfile
from xml.etree import ElementTree

import numpy as np

from ngcontact.errors import GeometryError

MAIN_XML = """<?xml version="1.0" encoding="UTF-8"?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">
  <Record1>
    <Revision>ISO5436 - 2000</Revision>
    <FeatureType>SUR</FeatureType>
    <Axes>
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx!r}</Increment><Offset>0</Offset></CX>
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dy!r}</Increment><Offset>0</Offset></CY>
      <CZ><AxisType>A</AxisType><DataType>D</DataType></CZ>
    </Axes>
  </Record1>
  <Record2>
    <Date>1970-01-01T00:00:00+00:00</Date>
    <Instrument><Manufacturer>ngcontact</Manufacturer><Model>{model}</Model><Serial>0</Serial>
    <Version>1</Version></Instrument>
    <CalibrationDate>1970-01-01T00:00:00+00:00</CalibrationDate>
    <ProbingSystem><Type>NonContacting</Type><Identification>none</Identification></ProbingSystem>
    <Comment>{comment}</Comment>
  </Record2>
  <Record3>
    <MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
    <DataLink><PointDataLink>bindata/data.bin</PointDataLink><MD5ChecksumPointData>{md5}</MD5ChecksumPointData>
    </DataLink>
  </Record3>
  <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>
</p:ISO5436_2>
"""


def write_x3p(path, heights, spacing: tuple[float, float], *, model: str = "ngcontact.geometry.x3p",
              comment: str = "height map") -> None:
    """Write ``heights[y, x]`` (metres) on a grid of ``spacing = (dx, dy)`` metres as an X3P file (a fixed date:
    the same heights give the same bytes)."""
    from xml.sax.saxutils import escape
    h = np.ascontiguousarray(np.asarray(heights, dtype="<f8"))
    data = h.tobytes()
    ny, nx = h.shape
    main = MAIN_XML.format(dx=float(spacing[0]), dy=float(spacing[1]), nx=nx, ny=ny, model=escape(model),
                           comment=escape(comment), md5=hashlib.md5(data).hexdigest()).encode("utf-8")
    stamp = (2026, 1, 1, 0, 0, 0)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for name, content in (("main.xml", main), ("bindata/data.bin", data),
                              ("md5checksum.hex", f"{hashlib.md5(main).hexdigest()} *main.xml\n".encode())):
            z.writestr(zipfile.ZipInfo(name, date_time=stamp), content, compress_type=zipfile.ZIP_DEFLATED)


#: the container's checksum entry (ISO 25178-72): ``<MD5 of main.xml> *main.xml``
CHECKSUM_FILE = "md5checksum.hex"
_MD5 = re.compile(r"[0-9a-fA-F]{32}")


def check_checksums(file, where: str) -> None:
    """Refuse an X3P file whose bytes differ from the MD5 checksums it states: a corrupted file.

    ISO 25178-72 makes ``md5checksum.hex`` part of the container: one line ``<32 hex digits> *main.xml``,
    the MD5 of ``main.xml`` (the name after the digits says which member is meant; none means
    ``main.xml``), and ``main.xml`` states the MD5 of the point data (``MD5ChecksumPointData`` beside
    ``PointDataLink``).  Each stated checksum must be the MD5 of its member (hexadecimal digits in either
    case), else :class:`~ngcontact.errors.GeometryError` under ``where`` names the file, the member, the
    actual and the stated checksum.  A file without ``md5checksum.hex``, or whose ``main.xml`` states no
    point-data checksum, is read as it is (older writers leave them out); a file that is not a zip holding
    ``main.xml`` is left to the reader.
    """
    if not zipfile.is_zipfile(file):
        return
    try:
        with zipfile.ZipFile(file) as z:
            names = set(z.namelist())
            if "main.xml" not in names:
                return
            stated = []
            if CHECKSUM_FILE in names:
                stated += [(member, digits, CHECKSUM_FILE) for member, digits in _listed(z.read(CHECKSUM_FILE), file,
                                                                                        where)]
            stated += _point_data(z.read("main.xml"))
            for member, digits, source in stated:
                if member not in names:
                    raise GeometryError(where, str(file), f"is corrupted: its {source} states the checksum of "
                                        f"{member!r}, which the file does not hold")
                actual = _md5(z, member)
                if actual != digits.lower():
                    raise GeometryError(where, str(file), f"is corrupted: the MD5 of its {member} is {actual}, but "
                                        f"its {source} states {digits.lower()}; read the scan from the instrument "
                                        "again")
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError) as err:
        raise GeometryError(where, str(file), f"is not a readable X3P container: {err}") from None


def _listed(text: bytes, file, where: str) -> list[tuple[str, str]]:
    """``(member, digits)`` of each line of ``md5checksum.hex``: ``digits [*]name``, name default main.xml."""
    out = []
    for line in text.decode("utf-8", "replace").splitlines():
        if not line.strip():
            continue
        digits, _, name = line.strip().partition(" ")
        if not _MD5.fullmatch(digits):
            shown = line.strip()[:64]
            raise GeometryError(where, str(file), f"is corrupted: its {CHECKSUM_FILE} holds {shown!r}, not an MD5 "
                                "checksum (32 hexadecimal digits)")
        out.append((name.strip().lstrip("*").strip() or "main.xml", digits))
    return out


def _point_data(main: bytes) -> list[tuple[str, str, str]]:
    """``(member, digits, "main.xml")`` of the point data's stated checksum, if ``main.xml`` states one."""
    try:
        root = ElementTree.fromstring(main)
    except ElementTree.ParseError:
        return []       # the reader names a main.xml it cannot parse
    link = root.find(".//DataLink")
    if link is None:
        return []
    member, digits = link.findtext("PointDataLink"), link.findtext("MD5ChecksumPointData")
    if not member or not digits or not _MD5.fullmatch(digits.strip()):
        return []
    return [(member.strip(), digits.strip(), "main.xml")]


def _md5(z: zipfile.ZipFile, member: str) -> str:
    """The MD5 of a member, read in blocks."""
    h = hashlib.md5()
    with z.open(member) as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()
