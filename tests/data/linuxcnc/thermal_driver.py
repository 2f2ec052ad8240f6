#!/usr/bin/python3
"""The "display" of the LinuxCNC thermal test: reset E-stop, switch on,
home, MDI mode, then drive the thermal model's temperature signals through
the rows of steps.json ({"axis": "z", "signals": [...], "rows": [[...], ...]})
and record, after each row, what LinuxCNC applies once it has settled.

One row per step: the test's HAL file gates each lowpass so that it takes
its input only in the one servo period after `thermal-step` toggles, and
counts those periods (`thermal-steps.count`). After a toggle the driver
waits until that count has moved on and the axis' external offset has
stopped at its request (`axis.L.eoffset` unchanged and within the ramp's
stopping distance `stop_mm` of `axis.L.eoffset-request`: the motion
controller ramps it at OFFSET_AV_RATIO of the axis' limits),
then reads the offset the model computed (the float and the counts), the
request, the applied offset and the joint's position command.
Writes result.json next to itself and exits, which shuts LinuxCNC down."""
import json
import os
import subprocess
import time

import machine

HERE = os.path.dirname(os.path.abspath(__file__))
result = {"points": []}


def halcmd(lines):
    """Runs halcmd commands (one process), returns what they print, line by line."""
    out = subprocess.run(["halcmd", "-f"], input="\n".join(lines) + "\n",
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError("halcmd %r: %s" % (lines, out.stderr.strip()))
    return out.stdout.split()


def number(text):
    """A value as halcmd prints it (bits as TRUE/FALSE), as a float."""
    return {"TRUE": 1.0, "FALSE": 0.0}.get(text) if text in ("TRUE", "FALSE") else float(text)


def read(names):
    """The values of signals and pins, as floats."""
    commands = [("gets %s" if name.startswith("thermal-") else "getp %s") % name for name in names]
    return dict(zip(names, (number(v) for v in halcmd(commands))))


try:
    steps = json.load(open(os.path.join(HERE, "steps.json")))
    axis, joint, signals, rows = steps["axis"], steps["joint"], steps["signals"], steps["rows"]
    machine.ready_in_mdi()
    names = ["thermal-steps", "thermal-offset", "thermal-offset-counts",
             "axis.%s.eoffset-request" % axis, "axis.%s.eoffset" % axis,
             "axis.%s.pos-cmd" % axis, "joint.%d.pos-cmd" % joint,
             "motion.eoffset-active"]
    for k, row in enumerate(rows):
        commands = ["sets %s %r" % (name, value) for name, value in zip(signals, row)]
        if k == 0:
            # The lags start at the first row (`thermal apply` starts them there).
            commands.append("sets thermal-load 1")
        commands.append("sets thermal-step %d" % ((k + 1) % 2))
        halcmd(commands)
        deadline = time.monotonic() + 20
        previous = None
        while True:
            time.sleep(0.01)
            point = read(names)
            taken = point["thermal-steps"] == k + 1
            # The request follows the counts one period later: wait for both.
            requested = abs(point["axis.%s.eoffset-request" % axis]
                            - point["thermal-offset-counts"] * steps["scale"]) < 1e-12
            # The ramp stops once within its stopping distance of the request.
            applied = point["axis.%s.eoffset" % axis]
            settled = (applied == previous and abs(
                applied - point["axis.%s.eoffset-request" % axis]) <= steps["stop_mm"])
            previous = applied
            if taken and requested and settled:
                break
            if time.monotonic() > deadline:
                raise RuntimeError("row %d: the offset did not settle: %r" % (k, point))
        if k == 0:
            halcmd(["sets thermal-load 0"])
        result["points"].append(point)
except Exception as error:  # reported to the Rust test, which fails on it
    shown = subprocess.run(["halcmd", "show", "thread"], capture_output=True, text=True)
    signals = subprocess.run(["halcmd", "show", "sig"], capture_output=True, text=True)
    result["error"] = "%r\n%s\n%s" % (error, shown.stdout, signals.stdout)
with open(os.path.join(HERE, "result.json"), "w") as out:
    json.dump(result, out)
