#!/usr/bin/env python3
"""A reader written from docs/state-format.md alone must accept the files demmat writes. Usage:
check_state_format.py DEMMAT DOC

The checksum is computed as the document describes it: FNV-1a over every byte before it, from the offset
basis and with the prime the document names (FNV-1a's standard 64-bit constants where it names none).
A state is made in a fresh temporary folder (removed at the end) and read: magic, version, the particle
and wall counts against the file's size, and the checksum. Only the standard library.
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

STANDARD_BASIS, STANDARD_PRIME = 14695981039346656037, 1099511628211


def fnv1a(data, basis, prime):
    h = basis
    for b in data:
        h = ((h ^ b) * prime) & 0xFFFFFFFFFFFFFFFF
    return h


def main():
    demmat, doc = os.path.abspath(sys.argv[1]), sys.argv[2]
    with open(doc, encoding="utf-8") as f:
        text = f.read()
    basis = re.search(r"offset basis (\d+)", text)
    prime = re.search(r"prime (\d+)", text)
    basis = int(basis.group(1)) if basis else STANDARD_BASIS
    prime = int(prime.group(1)) if prime else STANDARD_PRIME
    work = tempfile.mkdtemp(prefix="demmat_state_format_")
    try:
        scene = os.path.join(work, "bed.toml")
        subprocess.run([demmat, "scene", "dense-bed", "--n", "50", "-o", scene], check=True)
        state = os.path.join(work, "bed.state")
        subprocess.run([demmat, "run", scene, "--steps", "20", "--save", state, "-q"], check=True, stdout=subprocess.DEVNULL)
        with open(state, "rb") as f:
            data = f.read()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if data[:8] != b"DEMMATST":
        fail("the magic is not DEMMATST")
    version, reserved, _fingerprint, step, dt, n, walls = struct.unpack_from("<IIQqdQQ", data, 8)
    if version not in (1, 2) or reserved != 0 or n != 50 or walls != 6 or step != 20:
        fail(f"header: version {version}, reserved {reserved}, {n} particles, {walls} walls, step {step}")
    (stored,) = struct.unpack_from("<Q", data, len(data) - 8)
    computed = fnv1a(data[:-8], basis, prime)
    if stored != computed:
        fail(f"checksum {stored:#x} in the file, {computed:#x} by the document's FNV-1a (offset basis {basis}, prime {prime})")
    print(f"ok: the checksum follows the document (offset basis {basis}, prime {prime})")


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


if __name__ == "__main__":
    main()
