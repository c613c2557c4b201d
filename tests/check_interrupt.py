#!/usr/bin/env python3
"""Nothing half-written: interrupts `demmat run` while it writes each kind of output and checks what is
left. Usage: check_interrupt.py DEMMAT WORKDIR

A run of a 20000-particle bed writes a VTK snapshot (.vtp, ~4 MB) every step, the .pvd series after each,
and at the end the state (--save, ~6 MB) and the JSON summary. For each output kind and each of SIGINT,
SIGTERM and SIGKILL, the run is started over the outputs of a complete earlier run, the folder is watched
until that output's temporary file appears, and the signal is sent at once. Then every output must be the
previous file or a complete new one: the state loads (demmat checks its checksum), the JSON parses, the
.pvd parses and names only snapshots that exist and parse with every point. After SIGINT/SIGTERM no
temporary file may be left; after SIGKILL (which cannot be caught) one may, beside an intact file.
Last, a full disk (a file-size limit): the run must fail with a one-line error and leave the previous
files untouched. Only the standard library: any python3 runs it.
"""
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

N = 20000
STEPS = 3


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def main():
    demmat, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scene = os.path.join(work, "bed.toml")
    subprocess.run([demmat, "scene", "dense-bed", "--n", str(N), "-o", scene], check=True)
    out = os.path.join(work, "out")
    vtk = os.path.join(out, "vtk")
    state = os.path.join(out, "bed.state")
    summary = os.path.join(out, "run.json")
    run = [demmat, "run", scene, "--steps", str(STEPS), "--vtk", vtk, "--vtk-every", "1", "--save", state,
           "--json", summary, "-q"]
    # A scene that continues from the saved state: demmat itself checks that a state file is whole.
    cont = os.path.join(work, "continue.toml")
    with open(scene) as f:
        text = f.read()
    text = re.sub(r"\[particles\].*", '[particles]\nsource = "state"\nfile = "out/bed.state"\n', text, flags=re.S)
    with open(cont, "w") as f:
        f.write(text)

    subprocess.run(run, check=True, stdout=subprocess.DEVNULL)
    previous = snapshot_bytes(out)
    check_outputs(demmat, cont, out, vtk, state, summary, previous, allow_tmp=False, what="the complete run")

    targets = {  # output kind: pattern of its temporary file
        "vtp": re.compile(r"_\d+\.vtp\.tmp\d+$"),
        "pvd": re.compile(r"\.pvd\.tmp\d+$"),
        "state": re.compile(r"bed\.state\.tmp\d+$"),
        "json": re.compile(r"run\.json\.tmp\d+$"),
    }
    hits = 0
    report = []
    for kind, pattern in targets.items():
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            what = f"{sig.name} while writing the {kind}"
            for attempt in range(1, 6):
                p = subprocess.Popen(run, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
                seen = watch(p, out, pattern)
                if seen is None:  # finished before the file showed up: try again
                    p.wait()
                    continue
                p.send_signal(sig)
                _, err = p.communicate()
                break
            else:
                fail(f"{what}: the temporary file never showed up in 5 runs")
            if p.returncode == 0:
                note = "finished before the signal"
            elif p.returncode == -sig:
                note = "died of the signal"
            else:
                fail(f"{what}: exit {p.returncode}: {err.decode(errors='replace')}")
            left = [f for f in all_files(out) if ".tmp" in f]
            if sig == signal.SIGKILL and left:
                hits += 1
                note += f", left {len(left)} temporary file(s): killed mid-write"
            check_outputs(demmat, cont, out, vtk, state, summary, previous,
                          allow_tmp=(sig == signal.SIGKILL), what=what)
            for f in left:
                os.remove(f)
            report.append(f"{what}: attempt {attempt}, {note}; outputs intact")
    if hits == 0:
        fail("no SIGKILL landed while a file was being written: the test did not test anything")

    # A full disk: writes beyond 1 MB fail (RLIMIT_FSIZE; SIGXFSZ ignored so that write() returns EFBIG).
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (1 << 20, 1 << 20))
    before = snapshot_bytes(out)
    p = subprocess.run(run, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, preexec_fn=limit)
    err = p.stderr.decode(errors="replace").strip()
    if p.returncode != 2 or "\n" in err or "write failed" not in err:
        fail(f"full disk: expected exit 2 and a one-line 'write failed' error, got exit {p.returncode}: {err}")
    if snapshot_bytes(out) != before:
        fail("full disk: the previous files changed")
    report.append(f"full disk: exit 2, '{err}'; previous files untouched")
    print("\n".join(report))
    print(f"ok: {len(report)} cases, {hits} SIGKILLs landed mid-write")


def watch(p, folder, pattern, timeout=120.0):
    """Polls the folder until a file matching pattern exists; None if the run ends first."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for f in all_files(folder):
            if pattern.search(f):
                return f
        if p.poll() is not None:
            return None
        time.sleep(0.0002)
    p.kill()
    fail("the run did not write in time")


def all_files(folder):
    out = []
    for root, _, files in os.walk(folder):
        out.extend(os.path.join(root, f) for f in files)
    return out


def snapshot_bytes(folder):
    return {f: open(f, "rb").read() for f in all_files(folder)}


def check_outputs(demmat, cont, out, vtk, state, summary, previous, allow_tmp, what):
    files = all_files(out)
    tmp = [f for f in files if ".tmp" in f]
    if tmp and not allow_tmp:
        fail(f"{what}: temporary files left behind: {tmp}")
    for f in files:
        if f in tmp:
            continue
        if f not in previous:
            fail(f"{what}: unexpected file {f}")
        if f.endswith(".vtp"):
            check_vtp(f, what)
    # The state: the previous bytes or a complete new file (demmat verifies size, checksum and values).
    with open(state, "rb") as f:
        data = f.read()
    if data != previous[state]:
        r = subprocess.run([demmat, "run", cont, "--steps", "1", "-q"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE)
        if r.returncode != 0:
            fail(f"{what}: the state file does not load: {r.stderr.decode(errors='replace')}")
    try:
        with open(summary) as f:
            j = json.load(f)
        if "provenance" not in j or j.get("steps") != STEPS:
            fail(f"{what}: the JSON summary is incomplete")
    except ValueError as e:
        fail(f"{what}: the JSON summary does not parse: {e}")
    pvds = [f for f in files if f.endswith(".pvd")]
    if len(pvds) != 1:
        fail(f"{what}: expected one .pvd, found {pvds}")
    try:
        root = ET.parse(pvds[0]).getroot()
    except ET.ParseError as e:
        fail(f"{what}: the .pvd does not parse: {e}")
    for ds in root.iter("DataSet"):
        if not os.path.exists(os.path.join(vtk, ds.get("file"))):
            fail(f"{what}: the .pvd names a missing snapshot {ds.get('file')}")


def check_vtp(path, what):
    # The walls' file of a snapshot (<stem>_walls_<step>.vtp) holds the bed's six box faces, a quad each.
    n = 24 if "_walls_" in os.path.basename(path) else N
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        fail(f"{what}: {path} does not parse: {e}")
    piece = root.find("PolyData/Piece")
    if piece is None or int(piece.get("NumberOfPoints")) != n:
        fail(f"{what}: {path} does not hold {n} points")
    points = piece.find("Points/DataArray").text.split()
    if len(points) != 3 * n:
        fail(f"{what}: {path} holds {len(points) // 3} positions, not {n}")


if __name__ == "__main__":
    main()
