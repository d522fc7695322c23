#!/usr/bin/env python3
"""The worlds benchmark's tables over several runs pooled, and its detection curve over magnitude.

    python3 experiments/pool_worlds.py RUN.jsonl [RUN.jsonl ...]
    python3 experiments/pool_worlds.py --curve 0.5=m0.5.jsonl 1=k2.jsonl 2=m2.jsonl [--seeds 72000,72001]

Each RUN.jsonl is written by the worlds benchmark's `--json` (one world per line). Pooled, the
script prints the family table (with the oracle's drift excess cut beside the loop's), the null
table, and the oracle's cut against the loop's on the same axes. With `--curve`, one row per
magnitude over the effect worlds of each file (`--seeds`: only those seeds, for a run that holds
more worlds than the curve's).
"""

import json
import math
import statistics
import sys
from collections import OrderedDict

CHANNELS = {"accelerometer", "supply_voltage", "humidity", "air_pressure"}


class BadInput(Exception):
    pass


def load(paths, seeds=None):
    worlds = []
    for path in paths:
        try:
            with open(path) as f:
                for number, line in enumerate(f, 1):
                    if line.strip():
                        worlds.append(json.loads(line))
        except OSError as e:
            raise BadInput(f"{path}: {e.strerror}") from e
        except json.JSONDecodeError as e:
            raise BadInput(f"{path}, line {number}: not a worlds --json line ({e.msg})") from e
    return [w for w in worlds if seeds is None or w["seed"] in seeds]


def wilson(k, n, z=1.96):
    """Wilson's 95 % interval of k successes in n, in percent."""
    if n == 0:
        return (0.0, 0.0)
    p = k / n
    d = 1 + z * z / n
    c = p + z * z / (2 * n)
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return ((c - h) / d * 100, (c + h) / d * 100)


def span(values, axes=True):
    """ "median× (lowest×–highest×), n axes", or "–"."""
    if not values:
        return "–"
    text = f"{statistics.median(values):.2f}× ({min(values):.2f}×–{max(values):.2f}×)"
    return f"{text}, {len(values)} axes" if axes else text


def detectable(oracle):
    return bool(oracle) and oracle["gain"] > 0 and oracle["gain"] >= oracle["detectable_share"]


def oracle_cut(axis):
    """The oracle's cut where its loop admitted a term, else None."""
    oracle = axis.get("oracle")
    if oracle and oracle.get("terms") and oracle["cut"]["ratio"] > 0:
        return oracle["cut"]["ratio"]
    return None


def affected_axes(worlds):
    return [(w, a) for w in worlds if w["kind"] != "null" for a in w["axes"] if a["affected"]]


def family_tables(worlds):
    families = OrderedDict()
    for w in worlds:
        families.setdefault(w["kind"], []).append(w)
    print(
        "| family | worlds | affected axes | true regressor's gain, median (range) | oracle-detectable "
        "| right family first and significant among them | right family admitted | drift excess cut "
        "where a term was admitted, median (range) | oracle: drift excess cut where it admitted a "
        "term, median (range) | surely worse than 0.9× |"
    )
    print("|---|---:|---:|---|---:|---|---|---|---|---:|")
    total = {"affected": 0, "detectable": 0, "found": 0, "cuts": [], "oracle": [], "worse": 0}
    for family, ws in families.items():
        if family == "null":
            continue
        axes = affected_axes(ws)
        gains = [a["oracle"]["gain"] for _, a in axes if a.get("oracle")]
        det = [a for _, a in axes if detectable(a.get("oracle"))]
        found = sum(a["right_family"] and a["top_significant"] for a in det)
        cuts = [a["cut"]["ratio"] for _, a in axes if a["admitted"]]
        oracle = [c for c in (oracle_cut(a) for _, a in axes) if c is not None]
        worse = sum(a["cut"]["high"] < 0.9 for _, a in axes)
        admitted = sum(a["right_family_admitted"] for _, a in axes)
        gain = f"{statistics.median(gains):.2f} ({min(gains):.2f}–{max(gains):.2f})" if gains else "–"
        has_oracle = bool(gains)
        name = family if has_oracle else f"{family} (no oracle)"
        print(
            f"| {name} | {len(ws)} | {len(axes)} | {gain} | {len(det) if has_oracle else '–'} "
            f"| {f'{found} of {len(det)}' if det else '–'} | {admitted} of {len(axes)} "
            f"| {span(cuts)} | {span(oracle)} | {worse} |"
        )
        total["affected"] += len(axes)
        total["detectable"] += len(det)
        total["found"] += found
        total["cuts"] += cuts
        total["oracle"] += oracle
        total["worse"] += worse
    low, high = wilson(total["found"], total["detectable"])
    share = 100 * total["found"] / max(total["detectable"], 1)
    print(
        f"| **all** | | {total['affected']} | | **{total['detectable']}** "
        f"| **{total['found']} of {total['detectable']} ({share:.0f} %, {low:.0f}–{high:.0f} %)** | "
        f"| **{span(total['cuts'])}** | **{span(total['oracle'])}** | **{total['worse']}** |"
    )
    nulls = [a for w in families.get("null", []) for a in w["axes"]]
    if nulls:
        clean = sum(not a["any_significant"] for a in nulls)
        low, high = wilson(clean, len(nulls))
        admitted = sum(bool(a["admitted"]) for a in nulls)
        worse = sum(a["cut"]["high"] < 0.9 for a in nulls)
        cuts = [a["cut"]["ratio"] for a in nulls if a["admitted"]]
        print()
        print(
            "| null | worlds | axes | no effect significant | a term admitted (thermal response or "
            "effect) | surely worse than 0.9× | drift excess cut where a term was admitted, median "
            "(range) |"
        )
        print("|---|---:|---:|---|---|---:|---|")
        print(
            f"| null | {len(families['null'])} | {len(nulls)} | {clean} of {len(nulls)} "
            f"({100 * clean / len(nulls):.0f} %, {low:.0f}–{high:.0f} %) | {admitted} of {len(nulls)} "
            f"| {worse} | {span(cuts, axes=False)} |"
        )
    seconds = [w["loop_seconds"] for w in worlds]
    peak = max(w["loop_peak_rss_mb"] for w in worlds)
    print(
        f"\nloop: median {statistics.median(seconds):.1f} s, max {max(seconds):.1f} s; "
        f"peak {peak:.0f} MB; {len(worlds)} worlds"
    )
    axes = affected_axes(worlds)
    pairs = [(a["cut"]["ratio"], oracle_cut(a)) for _, a in axes if oracle_cut(a) is not None]
    truth = [
        a["oracle"]["cut"]["ratio"]
        for _, a in axes
        if a.get("oracle") and a["oracle"].get("admitted") and a["oracle"]["cut"]["ratio"] > 0
    ]
    print(
        f"the oracle where it admitted a term: {span([o for _, o in pairs])}; the loop on the same "
        f"axes: {span([b for b, _ in pairs if b > 0])}; the oracle where it admitted the truth: "
        f"{span(truth)}"
    )


def curve(rows, seeds):
    print(
        "| magnitude | affected axes | oracle-detectable | right family first and significant among "
        "them | channels | derived families | drift excess cut where a term was admitted, median "
        "| oracle: cut where it admitted a term, median | surely worse than 0.9× |"
    )
    print("|---|---:|---:|---|---|---|---|---|---:|")
    for magnitude, path in rows:
        axes = affected_axes(load([path], seeds))
        det = [(w, a) for w, a in axes if detectable(a.get("oracle"))]
        found = [(w, a["right_family"] and a["top_significant"]) for w, a in det]
        channels = [f for w, f in found if w["kind"] in CHANNELS]
        derived = [f for w, f in found if w["kind"] not in CHANNELS]
        cuts = [a["cut"]["ratio"] for _, a in axes if a["admitted"] and a["cut"]["ratio"] > 0]
        oracle = [c for c in (oracle_cut(a) for _, a in axes) if c is not None]
        worse = sum(a["cut"]["high"] < 0.9 for _, a in axes)
        k = sum(f for _, f in found)
        low, high = wilson(k, len(det))

        def median(values):
            return f"{statistics.median(values):.2f}× ({len(values)} axes)" if values else "–"

        print(
            f"| {magnitude}× | {len(axes)} | {len(det)} | {k} of {len(det)} "
            f"({100 * k / max(len(det), 1):.0f} %, {low:.0f}–{high:.0f} %) "
            f"| {sum(channels)} of {len(channels)} | {sum(derived)} of {len(derived)} "
            f"| {median(cuts)} | {median(oracle)} | {worse} |"
        )


def main(args):
    if not args or args[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if args else 2
    seeds = None
    if "--seeds" in args:
        i = args.index("--seeds")
        seeds = {int(s) for s in args[i + 1].split(",")}
        args = args[:i] + args[i + 2 :]
    if args[0] == "--curve":
        rows = [tuple(a.split("=", 1)) for a in args[1:]]
        bad = [a for a, r in zip(args[1:], rows) if len(r) != 2]
        if bad:
            print(f"pool_worlds.py: --curve takes MAGNITUDE=FILE, not {bad[0]!r}", file=sys.stderr)
            return 2
        curve(rows, seeds)
    else:
        family_tables(load(args, seeds))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except BadInput as e:
        print(f"pool_worlds.py: {e}", file=sys.stderr)
        sys.exit(2)
