#!/usr/bin/python3
"""No instruction beyond the x86-64 baseline in the linked programs (variants/CMakeLists.txt, "fast").

The fast variant and the mpi variant's ranks alone are compiled for this CPU, each as a shared object
that keeps its code, and its native copies of the inline and template code it shares with the others,
to itself. Every function the linked programs hold must therefore be baseline code: this disassembles
each program given and fails, naming the functions, on any AVX register (ymm, zmm, the mask registers k0-k7), any VEX- or EVEX-encoded
instruction (mnemonics v..., whatever the register), or an instruction of the extensions after the
baseline that GCC emits without vectors (BMI, BMI2, POPCNT, LZCNT, MOVBE, ADX).

usage: check_baseline_code.py [--skip REASON] BINARY...    exit 0: clean, 1: native code found, 77: skipped
"""
import re
import shutil
import subprocess
import sys

SKIP = 77
# tzcnt is left out: GCC's baseline ctz is `rep bsf`, which objdump prints as tzcnt.
SCALAR_EXTENSIONS = {"andn", "bextr", "blsi", "blsmsk", "blsr", "bzhi", "mulx", "pdep", "pext", "rorx", "sarx",
                     "shlx", "shrx", "popcnt", "lzcnt", "movbe", "adcx", "adox"}
BASELINE_V = {"verr", "verw"}  # the only baseline mnemonics that start with v
AVX_REGISTER = re.compile(r"%(?:[yz]mm\d+|k[0-7]\b)")
FUNCTION = re.compile(r"^[0-9a-f]+ <(.+)>:$")


def offending(line):
    """The reason an objdump instruction line is not baseline code, or None."""
    parts = line.split("\t")
    if len(parts) < 2:
        return None
    text = parts[-1].strip()
    words = text.split()
    while words and words[0] in ("lock", "rep", "repz", "repnz", "repe", "repne", "notrack", "bnd", "data16", "cs", "ds"):
        words = words[1:]
    if not words:
        return None
    mnemonic = words[0]
    if AVX_REGISTER.search(text):
        return "AVX register"
    if mnemonic.startswith("v") and mnemonic not in BASELINE_V:
        return "VEX/EVEX instruction"
    if mnemonic in SCALAR_EXTENSIONS:
        return "post-baseline instruction"
    return None


def check(objdump, binary):
    out = subprocess.run([objdump, "-d", "-w", "--no-show-raw-insn", "-C", binary], check=True, capture_output=True, text=True).stdout
    found = {}  # function -> (count, first instruction, reason)
    function = "?"
    for line in out.splitlines():
        m = FUNCTION.match(line)
        if m:
            function = m.group(1)
            continue
        why = offending(line)
        if why:
            count, first, reason = found.get(function, (0, line.strip(), why))
            found[function] = (count + 1, first, reason)
    return found


def main():
    binaries = sys.argv[1:]
    if binaries[:1] == ["--skip"]:
        print(f"SKIP: {binaries[1]}")
        return SKIP
    objdump = shutil.which("objdump")
    if objdump is None:
        print("SKIP: objdump not found")
        return SKIP
    failed = False
    for binary in binaries:
        found = check(objdump, binary)
        if not found:
            print(f"{binary}: baseline code only")
            continue
        failed = True
        print(f"{binary}: {len(found)} functions use instructions the x86-64 baseline does not have:")
        for function, (count, first, reason) in sorted(found.items(), key=lambda kv: -kv[1][0]):
            print(f"  {count:5d}  {function}\n         ({reason}; first: {first})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
