#!/usr/bin/env python3
"""`demmat dump` writes as `demmat run` does: whole or not at all. Usage: check_interrupt_dump.py DEMMAT

In a fresh temporary folder (removed at the end): a dump of a 2000-grain bed, a frame every step, is
interrupted by SIGINT and by SIGTERM once its temporary file has appeared; it must die of the signal and
leave no temporary file, and the dump from an earlier complete run must keep its bytes. Then names a
writer that reused a fixed temporary name would write through: a symbolic link `OUT.part -> victim`
and a read-only `OUT.part`, beside a complete dump; both must be left as they were. Only the standard
library: any python3 runs it.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def main():
    demmat = os.path.abspath(sys.argv[1])
    work = tempfile.mkdtemp(prefix="demmat_dump_")
    try:
        cases(demmat, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def cases(demmat, w):
    subprocess.run([demmat, "scene", "dense-bed", "--n", "2000", "-o", "bed.toml"], cwd=w, check=True)
    dump = [demmat, "dump", "bed.toml", "--steps", "100000", "--every", "1", "-o", "bed.dump"]
    subprocess.run([demmat, "dump", "bed.toml", "--steps", "2", "--every", "1", "-o", "bed.dump"], cwd=w, check=True)
    previous = read(w, "bed.dump")
    tmp = re.compile(r"^bed\.dump\.tmp\d+")
    report = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        p = subprocess.Popen(dump, cwd=w, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        end = time.monotonic() + 120
        while not any(tmp.match(f) for f in os.listdir(w)):
            if p.poll() is not None or time.monotonic() > end:
                p.kill()
                fail(f"the dump's temporary file never showed up (exit {p.poll()})")
            time.sleep(0.001)
        time.sleep(0.3)  # frames are being written
        p.send_signal(sig)
        _, err = p.communicate()
        if p.returncode != -sig:
            fail(f"{sig.name} during dump: exit {p.returncode}, expected death by the signal: {err.decode(errors='replace')}")
        left = [f for f in os.listdir(w) if tmp.match(f)]
        if left:
            fail(f"{sig.name} during dump left {left}")
        if read(w, "bed.dump") != previous:
            fail(f"{sig.name} during dump changed the previous dump")
        report.append(f"{sig.name} during dump: died of the signal, no temporary file, the previous dump intact")

    # Names a fixed temporary name would have written through or reused.
    with open(os.path.join(w, "victim"), "w") as f:
        f.write("victim\n")
    os.symlink("victim", os.path.join(w, "a.dump.part"))
    with open(os.path.join(w, "b.dump.part"), "w") as f:
        f.write("read-only\n")
    os.chmod(os.path.join(w, "b.dump.part"), 0o444)
    for out in ("a.dump", "b.dump"):
        subprocess.run([demmat, "dump", "bed.toml", "--steps", "2", "--every", "1", "-o", out], cwd=w, check=True)
        if read(w, out).count(b"ITEM: TIMESTEP") != 3:
            fail(f"dump -o {out}: not the three frames of a complete dump")
    if read(w, "victim") != b"victim\n" or os.readlink(os.path.join(w, "a.dump.part")) != "victim":
        fail("dump wrote through a symbolic link named like its temporary file")
    if read(w, "b.dump.part") != b"read-only\n":
        fail("dump reused a read-only file named like its temporary file")
    report.append("a symbolic link and a read-only file named OUT.part: left alone")
    print("\n".join(report))
    print("ok")


def read(w, name):
    with open(os.path.join(w, name), "rb") as f:
        return f.read()


if __name__ == "__main__":
    main()
