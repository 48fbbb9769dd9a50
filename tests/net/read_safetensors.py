#!/usr/bin/env python3
"""Independent reader of the safetensors format (standard library only), following the
checks of the reference implementation (huggingface/safetensors, Metadata::validate):
8-byte little-endian header length, a JSON object header starting with '{', string-only
__metadata__, known dtypes, byte counts equal to shape x dtype size, and data_offsets that,
sorted, tile the byte buffer exactly. The Python package is not installable here; this
script is how the tests check that what we write is what that package reads.

Prints one line per tensor: "<name> <dtype> <shape,comma-separated> <sum of values>",
then "metadata <key>=<value>" lines. Exits 1 with a message on any violation."""
import json
import struct
import sys

SIZES = {"F64": 8, "F32": 4, "F16": 2, "BF16": 2, "I64": 8, "I32": 4, "I16": 2, "I8": 1,
         "U8": 1, "BOOL": 1, "U16": 2, "U32": 4, "U64": 8}
FORMATS = {"F64": "d", "F32": "f", "F16": "e", "I64": "q", "I32": "i", "I16": "h", "I8": "b",
           "U8": "B", "BOOL": "?"}


def fail(message):
    print("invalid safetensors: " + message, file=sys.stderr)
    sys.exit(1)


def values(dtype, raw):
    if dtype == "BF16":
        halves = struct.unpack("<%dH" % (len(raw) // 2), raw)
        return [struct.unpack("<f", struct.pack("<I", h << 16))[0] for h in halves]
    return struct.unpack("<%d%s" % (len(raw) // SIZES[dtype], FORMATS[dtype]), raw)


def main(path):
    data = open(path, "rb").read()
    if len(data) < 8:
        fail("shorter than 8 bytes")
    (n,) = struct.unpack("<Q", data[:8])
    if n > 100_000_000 or 8 + n > len(data):
        fail("header length %d does not fit" % n)
    header_bytes = data[8:8 + n]
    if not header_bytes.startswith(b"{"):
        fail("header does not start with '{'")
    header = json.loads(header_bytes.decode("utf-8"))
    buffer = data[8 + n:]
    metadata = header.pop("__metadata__", {})
    if not all(isinstance(v, str) for v in metadata.values()):
        fail("__metadata__ values must be strings")
    entries = []
    for name, info in header.items():
        dtype, shape, (begin, end) = info["dtype"], info["shape"], info["data_offsets"]
        if dtype not in SIZES:
            fail("unknown dtype " + dtype)
        count = 1
        for d in shape:
            count *= d
        if end - begin != count * SIZES[dtype]:
            fail("%s: %d bytes for shape %s" % (name, end - begin, shape))
        entries.append((begin, end, name, dtype, shape))
    entries.sort()
    position = 0
    for begin, end, name, _, _ in entries:
        if begin != position:
            fail("%s starts at %d, expected %d" % (name, begin, position))
        position = end
    if position != len(buffer):
        fail("tensors cover %d of %d buffer bytes" % (position, len(buffer)))
    for begin, end, name, dtype, shape in sorted(entries, key=lambda e: e[2]):
        total = sum(values(dtype, buffer[begin:end]))
        print("%s %s %s %.9g" % (name, dtype, ",".join(map(str, shape)), total))
    for key in sorted(metadata):
        print("metadata %s=%s" % (key, metadata[key]))


if __name__ == "__main__":
    main(sys.argv[1])
