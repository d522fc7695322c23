#!/usr/bin/env python3
"""Writes the shared test vectors (testdata/vectors.json) as C arrays for the C example.

Usage: vectors_to_c.py VECTORS_JSON OUT_C

The models are written as their firmware images (the bytes the host decodes); the cases as
arrays of IEEE-754 bit patterns, as the file stores them. Cases of the polynomial baselines,
which the C interface does not run, are left out and counted.
"""
import json
import sys

RUN = {"modified", "recommended"}  # model kinds the C interface runs


def words(values, per_line=8):
    lines = []
    for i in range(0, len(values), per_line):
        lines.append("    " + ", ".join(f"0x{v:08x}u" for v in values[i : i + per_line]) + ",")
    return "\n".join(lines)


def main(path, out):
    with open(path, encoding="utf-8") as f:
        vectors = json.load(f)
    kinds = {m["name"]: m["kind"] for m in vectors["models"]}
    run = [m for m in vectors["models"] if m["kind"] in RUN]
    index = {m["name"]: i for i, m in enumerate(run)}
    cases = [c for c in vectors["cases"] if kinds[c["model"]] in RUN]
    skipped = len(vectors["cases"]) - len(cases)
    c = ['/* Generated from testdata/vectors.json by vectors_to_c.py: do not edit. */',
         '#include "vectors.h"', ""]
    for m in run:
        image = bytes.fromhex(m["image_hex"])
        c.append(f"static const uint8_t image_{m['name']}[{len(image)}] = {{")
        for i in range(0, len(image), 16):
            c.append("    " + ", ".join(f"0x{b:02x}" for b in image[i : i + 16]) + ",")
        c.append("};")
    c.append(f"const struct vector_model vector_models[{len(run)}] = {{")
    for m in run:
        c.append(f'    {{"{m["name"]}", image_{m["name"]}, sizeof image_{m["name"]}}},')
    c.append("};")
    for n, case in enumerate(cases):
        flat = [v for s in case["samples"] for v in s]
        c.append(f"static const uint32_t samples_{n}[{len(flat)}] = {{\n{words(flat)}\n}};")
        flat = [v for e in case["expected"] for v in e]
        c.append(f"static const uint32_t expected_{n}[{len(flat)}] = {{\n{words(flat)}\n}};")
        if case.get("aux"):
            flat = [v for a in case["aux"] for v in a]
            c.append(f"static const uint32_t aux_{n}[{len(flat)}] = {{\n{words(flat)}\n}};")
    c.append(f"const struct vector_case vector_cases[{len(cases)}] = {{")
    for n, case in enumerate(cases):
        on = case.get("switch_on_raw")
        previous = case.get("previous")
        c.append("    {")
        c.append(f'        .name = "{case["name"]}",')
        c.append(f"        .model = {index[case['model']]},")
        c.append(f"        .powered_on = {1 if on else 0},")
        c.append(f"        .switch_on_raw = {{{', '.join(f'0x{v:08x}u' for v in (on or [0, 0, 0]))}}},")
        c.append(f"        .has_previous = {1 if previous else 0},")
        flat = [v for axis in (previous or [[0, 0]] * 3) for v in axis]
        c.append(f"        .previous = {{{', '.join(f'0x{v:08x}u' for v in flat)}}},")
        c.append(f"        .power_on_fails = {1 if case['power_on_fails'] else 0},")
        c.append(f"        .count = {len(case['samples'])},")
        c.append(f"        .samples = samples_{n},")
        c.append(f"        .expected = expected_{n},")
        c.append(f"        .aux = {'aux_' + str(n) if case.get('aux') else 'NULL'},")
        c.append("    },")
    c.append("};")
    c.append(f"const size_t vector_case_count = {len(cases)};")
    c.append(f"const size_t vector_cases_skipped = {skipped};")
    with open(out, "w", encoding="utf-8") as f:
        f.write("\n".join(c) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
