#!/usr/bin/python3
"""The "display" of the LinuxCNC test: reset E-stop, switch on, home, then
move the axis of positions.json ({"axis": "X", "positions": [...]}; joint 0)
to each of its positions (MDI G1) and record, after each
move, the correction LinuxCNC applies (sum2.0.out = motor-pos-cmd − pos-cmd),
pos-cmd, motor-offset and the screw-comp pins backlash-corr (the correction
computed) and backlash-filt (the correction applied), read with halcmd.
Writes result.json next to itself and exits, which shuts LinuxCNC down."""
import json
import os
import subprocess
import time

import machine

HERE = os.path.dirname(os.path.abspath(__file__))
result = {"points": []}


def getp(pin):
    return float(subprocess.check_output(["halcmd", "getp", pin]).decode().strip())


try:
    moves = json.load(open(os.path.join(HERE, "positions.json")))
    axis, positions = moves["axis"], moves["positions"]
    s, c = machine.ready_in_mdi()
    for x in positions:
        c.mdi("G1 %s%s F30000" % (axis, x))
        if c.wait_complete(60) == -1:
            raise RuntimeError("move to %s%s timed out" % (axis, x))
        time.sleep(0.05)  # let the backlash filter settle on the new correction
        result["points"].append({
            "x": x,
            "correction": getp("sum2.0.out"),
            "pos_cmd": getp("joint.0.pos-cmd"),
            "motor_offset": getp("joint.0.motor-offset"),
            "computed": getp("joint.0.backlash-corr"),
            "applied": getp("joint.0.backlash-filt"),
        })
except Exception as error:  # reported to the Rust test, which fails on it
    result["error"] = repr(error)
with open(os.path.join(HERE, "result.json"), "w") as out:
    json.dump(result, out)
