"""A minimal X3P file (ISO 25178-72 / ISO 5436-2): a height map written as an instrument would write its scan.

Used by the tests of measured topographies (:mod:`ngcontact.geometry.topography`) and by the script that
writes the shipped scan, so that both read the heights back through SurfaceTopography's reader, the
route of a real instrument's file.

The container is a zip of ``main.xml`` (the axes: ``CX``, ``CY`` incremental with their spacing in metres,
``CZ`` absolute heights in metres; the matrix dimensions and the link to the data) and the binary heights
``bindata/data.bin``: little-endian doubles, ``x`` running fastest (rows of constant ``y``), and the MD5
checksums the standard asks for.
"""
from __future__ import annotations

import hashlib
import zipfile

import numpy as np

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
