#!/usr/bin/env python3
"""Outputs that are not regular files, and every name a run writes. Usage: check_outputs.py DEMMAT

Everything happens in a fresh temporary folder (tempfile.mkdtemp), removed at the end; the device node
is made there by mknod (as root; where mknod is not allowed that part is skipped and said so), so no
device of the machine is ever touched. Checked, each a case that failed before its fix:
- an output (run --json/--save, scene -o, bench --json, export-lammps, import-lammps, dump) that is a
  character device or a FIFO is refused before any work (exit 2, one line) and stays what it was;
  --log, a stream written in place, writes into the device and leaves it a device;
- '-' as --json or --log is standard output (no file named '-'); --save - is refused;
- an empty name (--json '', --save '', --vtk '', --log '', -o '') is refused;
- a legal 255-byte output name is written (the temporary name fits too), a 256-byte one refused first;
- a VTK snapshot name of the run that is the scene, the state or another output, or a folder, is
  refused before the run, for particles and walls snapshots alike;
- a second run on a --log that a run holds is refused, the holder's log untouched.
Only the standard library: any python3 runs it.
"""
import fcntl
import os
import shutil
import stat
import subprocess
import sys
import tempfile

DEMMAT = None
failures = []


def run(args, cwd, expect_rc, expect_text=None, what=None):
    p = subprocess.run([DEMMAT] + args, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=120)
    err = p.stderr.decode(errors="replace").strip()
    what = what or " ".join(args)
    if p.returncode != expect_rc:
        failures.append(f"{what}: exit {p.returncode}, expected {expect_rc}: {err}")
    elif expect_rc == 2 and ("\n" in err or (expect_text and expect_text not in err)):
        failures.append(f"{what}: expected one line containing '{expect_text}', got: {err}")
    return p


def main():
    global DEMMAT
    DEMMAT = os.path.abspath(sys.argv[1])
    work = tempfile.mkdtemp(prefix="demmat_outputs_")
    try:
        cases(work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if failures:
        print("FAIL:\n" + "\n".join(failures), file=sys.stderr)
        sys.exit(1)
    print("ok")


def cases(w):
    run(["scene", "drop", "-o", "drop.toml"], w, 0)
    run(["run", "drop.toml", "--steps", "3", "-q", "--save", "drop.state"], w, 0)
    run(["export-lammps", "drop.toml", "-o", "peer/drop.data"], w, 0)
    short = ["run", "drop.toml", "--steps", "3", "-q"]

    # Special files as outputs: a FIFO always, a character device (/dev/null's numbers) where mknod works.
    specials = [("fifo", "a pipe (FIFO)")]
    os.mkfifo(os.path.join(w, "fifo"))
    try:
        os.mknod(os.path.join(w, "null"), 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        specials.append(("null", "a character device"))
    except (PermissionError, OSError) as e:
        print(f"skipped the device node (mknod not allowed here: {e}); the FIFO cases run")
    for node, kind in specials:
        was = os.lstat(os.path.join(w, node)).st_mode
        for args in (short + ["--json", node], short + ["--save", node], ["scene", "drop", "-o", node],
                     ["bench", "drop.toml", "--variants", "arrays", "--steps", "1", "--repetitions", "1", "--json", node],
                     ["import-lammps", "peer/drop.data", "--scene", "drop.toml", "-o", node],
                     ["dump", "drop.toml", "--steps", "2", "-o", node]):
            run(args, w, 2, f"{node}: is {kind}, not a regular file")
        run(["export-lammps", "drop.toml", "-o", node], w, 2, "not a regular file")
        if os.lstat(os.path.join(w, node)).st_mode != was:
            failures.append(f"{node}: no longer {kind} after the refused runs")
    if any(n == "null" for n, _ in specials):  # the log is written in place: into the device, which stays one
        run(short + ["--log", "null"], w, 0)
        if not stat.S_ISCHR(os.lstat(os.path.join(w, "null")).st_mode):
            failures.append("--log into a device node replaced the node")

    # '-': standard output for --json and --log, and no file named '-'.
    p = run(short + ["--json", "-"], w, 0)
    if not p.stdout.startswith(b"{") or b"variant arrays" not in p.stderr:
        failures.append("--json -: the JSON is not on standard output, or the report not on standard error")
    p = run(short + ["--log", "-"], w, 0)
    if not p.stdout.startswith(b"step,time,"):
        failures.append("--log -: the rows are not on standard output")
    run(short + ["--save", "-"], w, 2, "--save -: a state file is binary")
    run(short + ["--json", "-", "--log", "-"], w, 2, "both ask for standard output")
    if os.path.exists(os.path.join(w, "-")):
        failures.append("a file named '-' was written")

    # Empty names.
    for opt in ("--json", "--save", "--vtk", "--log"):
        run(short + [opt, ""], w, 2, f"{opt}: an empty name")
    run(["scene", "drop", "-o", ""], w, 2, "an empty name")

    # The longest legal name is written whole (its temporary name is shortened to fit); one more is refused.
    run(short + ["--json", "j" * 255], w, 0)
    if not os.path.isfile(os.path.join(w, "j" * 255)):
        failures.append("--json with a 255-byte name wrote nothing")
    run(short + ["--json", "k" * 256], w, 2, "more than the 255 a file name may have")

    # Every snapshot name of the run, checked before it starts.
    os.makedirs(os.path.join(w, "v"))
    shutil.copy(os.path.join(w, "drop.toml"), os.path.join(w, "v", "drop_000000003.vtp"))
    run(["run", "drop_000000003.vtp", "--steps", "3", "-q", "--vtk", "."], os.path.join(w, "v"), 2,
        "the snapshot of step 3 would be scene file")
    with open(os.path.join(w, "drop.toml")) as f:
        text = f.read()
    with open(os.path.join(w, "v", "cont.toml"), "w") as f:
        f.write(text.split("[particles]")[0] + '[particles]\nsource = "state"\nfile = "drop_walls_000000004.vtp"\n')
    shutil.copy(os.path.join(w, "drop.state"), os.path.join(w, "v", "drop_walls_000000004.vtp"))
    run(["run", "cont.toml", "--steps", "2", "-q", "--vtk", "."], os.path.join(w, "v"), 2,
        "the snapshot of step 4 would be state file")
    run(short + ["--vtk", "v2", "--json", "v2/drop_000000002.vtp"], w, 2, "the snapshot of step 2 would be the --json file")
    os.makedirs(os.path.join(w, "v3", "drop_walls_000000002.vtp"))
    run(short + ["--vtk", "v3", "--vtk-every", "1"], w, 2, "drop_walls_000000002.vtp, where the snapshot of step 2 goes")
    for f in ("drop_000000003.vtp", "drop_walls_000000004.vtp"):
        with open(os.path.join(w, "v", f), "rb") as a, open(os.path.join(w, "drop.toml" if "walls" not in f else "drop.state"), "rb") as b:
            if a.read() != b.read():
                failures.append(f"the input {f} was overwritten")

    # One log, one run: a run that finds the log locked by another is refused and leaves it alone.
    log = os.path.join(w, "held.csv")
    with open(log, "w") as f:
        f.write("the holder's rows\n")
        f.flush()
        fcntl.flock(f, fcntl.LOCK_EX)
        run(short + ["--log", "held.csv"], w, 2, "another run is writing this log")
    with open(log) as f:
        if f.read() != "the holder's rows\n":
            failures.append("a refused --log truncated the log another run holds")


if __name__ == "__main__":
    main()
