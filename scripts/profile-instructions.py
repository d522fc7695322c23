#!/usr/bin/env python3
"""Where the instructions of one counted interval go: the profile behind docs/embedded.md.

Runs the firmware's `count` binary under QEMU like `count-instructions.py`, keeps the executed
addresses between the markers of one interval, and folds them by function and by source line
(`llvm-objdump --line-numbers`), per corrected sample. With --listing, prints the disassembly of
every executed instruction with its count per sample.

Usage: scripts/profile-instructions.py [--interval N] [--listing] [path/to/count.elf]
(N is the interval's first marker id as the firmware prints it: 9 = extended, 1 s apart.)
"""

import collections
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
count = __import__("count-instructions")


def disassembly(elf):
    """Per address: (function, source line, instruction text)."""
    text = subprocess.check_output(
        [count.llvm_tool("llvm-objdump"), "-d", "--line-numbers", "--no-show-raw-insn", elf],
        text=True)
    rows = {}
    function, line = "?", "?"
    for row in text.splitlines():
        if m := re.match(r"^[0-9a-f]+ <(.+)>:$", row):
            function = m.group(1)
        elif row.startswith("; /"):
            path, _, number = row[2:].rpartition(":")
            line = f"{'/'.join(path.split('/')[-2:])}:{number}"
        elif m := re.match(r"^\s+([0-9a-f]+):\s+(.*)$", row):
            rows[int(m.group(1), 16)] = (function, line, m.group(2).strip())
    return rows


def short(function):
    """A legacy-mangled Rust name (`_ZN<len><part>...E`) as `part::part`, without its hash."""
    parts, rest = [], function.removeprefix("_ZN")
    while m := re.match(r"(\d+)", rest):
        n = int(m.group(1))
        parts.append(rest[m.end():m.end() + n])
        rest = rest[m.end() + n:]
    parts = [p for p in parts if not re.fullmatch(r"h[0-9a-f]{16}", p)] or [function]
    name = "::".join(parts[-3:])
    for code, char in (("$LT$", "<"), ("$GT$", ">"), ("$u20$", " "), ("$C$", ","), ("$RF$", "&"),
                       ("..", "::")):
        name = name.replace(code, char)
    return name


def main():
    args = sys.argv[1:]
    interval, listing = 9, False
    while args[:1] and args[0].startswith("--"):
        if args[0] == "--interval":
            interval, args = int(args[1]), args[2:]
        elif args[0] == "--listing":
            listing, args = True, args[1:]
        else:
            sys.exit(__doc__)
    elf = args[0] if args else count.ELF
    marker = count.marker_address(elf)
    hits = collections.Counter()
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
        pc = re.compile(r"\[[0-9a-f]+/([0-9a-f]+)/")
        markers = 0
        with open(log) as lines:
            for line in lines:
                match = pc.search(line)
                if not match:
                    continue
                address = int(match.group(1), 16)
                if address == marker:
                    markers += 1
                    continue
                if markers == interval:
                    hits[address] += 1
    rows = disassembly(elf)
    total = sum(hits.values()) / samples
    print(f"interval {interval}: {total:.1f} instructions per sample (marker body excluded)")
    by_function, by_line = collections.Counter(), collections.Counter()
    for address, n in hits.items():
        function, line, _ = rows.get(address, ("?", "?", "?"))
        by_function[short(function)] += n
        by_line[(short(function), line)] += n
    print("\nby function:")
    for function, n in by_function.most_common():
        print(f"  {n / samples:8.1f}  {function}")
    print("\nby source line (innermost inlined line):")
    for (function, line), n in by_line.most_common(60):
        print(f"  {n / samples:8.1f}  {line:48} {function}")
    if listing:
        print("\nexecuted instructions (count per sample):")
        for address in sorted(hits):
            function, line, text = rows.get(address, ("?", "?", "?"))
            print(f"  {hits[address] / samples:7.2f}  {address:6x}  {text:48} {line}")


if __name__ == "__main__":
    main()
