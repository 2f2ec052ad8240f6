"""What both LinuxCNC test drivers (driver.py, thermal_driver.py) do first:
reset E-stop, switch on, home every joint, and go to MDI mode (coordinated
motion, where a move and the axis' external offset both apply)."""
import time

import linuxcnc


def ready_in_mdi():
    """Switches the machine on, homes it and selects MDI; returns (stat, command)."""
    s = linuxcnc.stat()
    c = linuxcnc.command()
    c.state(linuxcnc.STATE_ESTOP_RESET)
    c.wait_complete(20)
    c.state(linuxcnc.STATE_ON)
    c.wait_complete(20)
    c.mode(linuxcnc.MODE_MANUAL)
    c.wait_complete(20)
    c.home(-1)
    c.wait_complete(20)
    for _ in range(400):
        s.poll()
        if all(s.homed[:3]):
            break
        time.sleep(0.05)
    else:
        raise RuntimeError("the joints did not home")
    c.mode(linuxcnc.MODE_MDI)
    c.wait_complete(20)
    return s, c
