#!/usr/bin/env python3
"""Counts instructions the emulated Cortex-M4 executes per corrected 3-axis sample.

Runs the firmware's `count` binary under QEMU with one instruction per translation block
(`-singlestep`) and an execution log (`-d exec,nochain`): every executed instruction is one
`Trace` line. The firmware calls `gyrodrift_marker` before and after correcting N samples with each
model; the instructions between two marker entries, divided by N, are the cost per sample (the loop
and call overhead included, so the figure is an upper bound of the corrector alone).

Usage: scripts/count-instructions.py [--max-modified N] [path/to/count.elf]
With --max-modified, exits non-zero if the modified model needs more than N instructions per sample
(instruction counts are deterministic for a given binary, so this is a regression gate, not a timing).
"""

import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ELF = os.path.join(ROOT, "embedded/target/thumbv7em-none-eabihf/release/count")


def llvm_tool(name):
    sysroot = subprocess.check_output(["rustc", "--print", "sysroot"], text=True).strip()
    return os.path.join(sysroot, "lib/rustlib/x86_64-unknown-linux-gnu/bin", name)


def marker_address(elf):
    for line in subprocess.check_output([llvm_tool("llvm-nm"), elf], text=True).splitlines():
        address, _, name = line.split()
        if name == "gyrodrift_marker":
            return int(address, 16) & ~1
    sys.exit("gyrodrift_marker not found in " + elf)


def main():
    args = sys.argv[1:]
    limit = None
    if args[:1] == ["--max-modified"]:
        limit = float(args[1])
        args = args[2:]
    elf = args[0] if args else ELF
    marker = marker_address(elf)
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "exec.log")
        run = subprocess.run(
            ["qemu-system-arm", "-cpu", "cortex-m4", "-machine", "mps2-an386", "-nographic",
             "-semihosting-config", "enable=on,target=native", "-singlestep",
             "-d", "exec,nochain", "-D", log, "-kernel", elf],
            capture_output=True, text=True, timeout=600)
        if run.returncode != 0:
            sys.exit("firmware failed:\n" + run.stdout + run.stderr)
        samples = int(re.search(r"samples per interval: (\d+)", run.stdout).group(1))
        labels = dict(re.findall(r"interval (\d+): (.+)", run.stdout))
        pc = re.compile(r"\[[0-9a-f]+/([0-9a-f]+)/")
        hits = []
        count = 0
        with open(log) as lines:
            for line in lines:
                match = pc.search(line)
                if not match:
                    continue
                count += 1
                if int(match.group(1), 16) == marker:
                    hits.append(count)
    if len(hits) < 2:
        sys.exit("markers not seen in the execution log")
    print(f"instructions per 3-axis corrected sample (QEMU 7.2 mps2-an386, -singlestep exec log, {samples} samples per interval):")
    for index in range(0, len(hits) - 1, 2):
        label = labels.get(str(index + 1), f"interval {index + 1}")
        per_sample = (hits[index + 1] - hits[index]) / samples
        print(f"  {label}: {per_sample:.1f}")
        if limit is not None and label.startswith("modified") and per_sample > limit:
            sys.exit(f"modified model needs {per_sample:.1f} instructions per sample, more than {limit}")


if __name__ == "__main__":
    main()
