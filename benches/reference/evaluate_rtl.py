#!/usr/bin/env python3
"""A plain-Python reference for `axcomp evaluate`: reads a Renishaw .rtl
(../shared/spec/renishaw-rtl.md: targets in mm, deviations in µm) and prints
the ISO 230-2 figures (../shared/spec/iso230-2.md), standard library only.

It is the yardstick of the evaluate speed figure (axcomp reads and evaluates
a 10 000-target x 10-run file at least 10 times faster than this script,
whole process) and a second, independent implementation of the figures:

    python3 benches/reference/evaluate_rtl.py FILE.rtl

prints one line per axis figure, in µm, to compare with `axcomp evaluate
FILE.rtl --json` (`figures_um`).
"""

import math
import sys


def read_rtl(path):
    targets = []
    readings = {}  # run -> {target index: deviation in µm}
    section = None
    in_targets = in_data = False
    with open(path, encoding="latin-1") as f:
        for raw in f:
            line = raw.strip()
            if line.endswith("::"):
                section = line
                in_targets = in_data = False
                continue
            if section == "TARGET DATA::":
                if line.startswith("Targets"):
                    in_targets = True
                    continue
                if line.startswith("Flags"):
                    in_targets = False
                    continue
                if in_targets and line:
                    targets.extend(float(t) for t in line.split())
            elif section == "DEVIATIONS::":
                if line.startswith("Run Target Data"):
                    in_data = True
                    continue
                if in_data and line:
                    run, target, value = line.split()[:3]
                    readings.setdefault(int(run), {})[int(target) - 1] = float(value)
    return targets, readings


def direction_of(run_readings):
    # A run that starts at the first target moves up (the order it was read in).
    first = next(iter(run_readings))
    return "up" if first == 0 else "down"


def stats(values):
    n = len(values)
    mean = sum(values) / n
    s = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1)) if n > 1 else None
    return mean, s


def evaluate(targets, readings):
    by_direction = {"up": [], "down": []}
    for run in sorted(readings):
        by_direction[direction_of(readings[run])].append(readings[run])
    per_target = []
    for i in range(len(targets)):
        up = stats([r[i] for r in by_direction["up"]])
        down = stats([r[i] for r in by_direction["down"]])
        mean = (up[0] + down[0]) / 2
        b = up[0] - down[0]
        r_up, r_down = 4 * up[1], 4 * down[1]
        r = max(2 * up[1] + 2 * down[1] + abs(b), r_up, r_down)
        per_target.append((up, down, mean, b, r_up, r_down, r))
    hi_up = max(t[0][0] + 2 * t[0][1] for t in per_target)
    lo_up = min(t[0][0] - 2 * t[0][1] for t in per_target)
    hi_down = max(t[1][0] + 2 * t[1][1] for t in per_target)
    lo_down = min(t[1][0] - 2 * t[1][1] for t in per_target)
    means_up = [t[0][0] for t in per_target]
    means_down = [t[1][0] for t in per_target]
    means = [t[2] for t in per_target]
    bs = [t[3] for t in per_target]
    return {
        "A": max(hi_up, hi_down) - min(lo_up, lo_down),
        "A_up": hi_up - lo_up,
        "A_down": hi_down - lo_down,
        "E": max(means_up + means_down) - min(means_up + means_down),
        "E_up": max(means_up) - min(means_up),
        "E_down": max(means_down) - min(means_down),
        "M": max(means) - min(means),
        "R": max(t[6] for t in per_target),
        "R_up": max(t[4] for t in per_target),
        "R_down": max(t[5] for t in per_target),
        "B": max(abs(b) for b in bs),
        "B_mean": sum(bs) / len(bs),
    }


def main():
    targets, readings = read_rtl(sys.argv[1])
    for name, value in evaluate(targets, readings).items():
        print(f"{name}_um {value:.6f}")


if __name__ == "__main__":
    main()
