#!/usr/bin/env python3
"""The decompression-bomb fixture for hysid's .mat reader test.

Writes crates/hysid-tests/tests/data/bomb_40MiB.zlib: the zlib stream (level 9, 40 783 bytes)
of one MAT-file element of 40 MiB of zeros (type 14, miMATRIX, with a 40 MiB length). The
test puts it in a miCOMPRESSED element behind a real header; the reader must refuse it
before inflating it all. Kept as a file because compressing 40 MiB inside the test, whose
code is built without optimisation, took three seconds of every test run.

Run:  python3 tools/reference/bomb_fixture.py
"""
import struct
import zlib

size = 40 << 20
element = struct.pack("<II", 14, size) + bytes(size)
with open("crates/hysid-tests/tests/data/bomb_40MiB.zlib", "wb") as f:
    f.write(zlib.compress(element, 9))
