#!/usr/bin/env python3
"""The diagnosis's significance threshold, calibrated on null worlds, and what it would find.

    python3 experiments/null_threshold.py NULLS.jsonl [EFFECTS.jsonl] [--level 0.05]

NULLS.jsonl and EFFECTS.jsonl are written by the worlds benchmark's `--json` (one world per line,
every axis with its whole ranking). For each statistic the loop could threshold — the top
fold-stable candidate's out-of-sample explained share, and its p-value — the script takes the
null worlds' axes, finds the threshold that leaves at most `level` of them with a "significant"
top candidate, and, given effect worlds drawn from other seeds, counts per family the affected
axes whose top candidate names the right family and passes that threshold.
"""
import json
import sys
from collections import defaultdict


def load(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def top_stable(axis):
    """The best fold-stable effect (the unit's own thermal response aside) with a positive
    explained share, or None."""
    for ranked, right in axis["ranking"]:
        if ranked.get("thermal_response"):
            continue
        if ranked["stable"] and ranked["explained"] > 0:
            return ranked, right
    return None


def quantile(values, q):
    values = sorted(values)
    if not values:
        return float("nan")
    k = min(len(values) - 1, max(0, int(round(q * (len(values) - 1)))))
    return values[k]


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    level = 0.05
    if "--level" in sys.argv:
        level = float(sys.argv[sys.argv.index("--level") + 1])
    nulls = load(args[0])
    effects = load(args[1]) if len(args) > 1 else []
    null_axes = [a for w in nulls for a in w["axes"]]
    explained = [t[0]["explained"] if (t := top_stable(a)) else 0.0 for a in null_axes]
    # The smallest threshold that no more than `level` of the null axes reach.
    threshold = quantile(explained, 1.0 - level)
    print(f"null axes: {len(null_axes)} from {len(nulls)} worlds")
    print(f"top stable explained share on null axes: median {quantile(explained, 0.5):.3f}, "
          f"95th percentile {quantile(explained, 0.95):.3f}, max {max(explained):.3f}")
    print(f"threshold at level {level}: explained > {threshold:.3f}")
    if not effects:
        return
    by_family = defaultdict(lambda: [0, 0, 0, 0])
    for w in effects:
        for a in w["axes"]:
            if not a["affected"]:
                continue
            row = by_family[w["kind"]]
            row[0] += 1
            top = top_stable(a)
            if top and top[1]:
                row[1] += 1
                if top[0]["explained"] > threshold:
                    row[2] += 1
            ranks = [i for i, (_, right) in enumerate(a["ranking"]) if right]
            if ranks and ranks[0] < 3:
                row[3] += 1
    print("| family | affected axes | right family first (stable) | … and above the null threshold | right family in the top 3 |")
    print("|---|---:|---:|---:|---:|")
    for family, (n, first, found, top3) in sorted(by_family.items()):
        print(f"| {family} | {n} | {first} | {found} | {top3} |")


if __name__ == "__main__":
    main()
