"""Quaternion helpers shared by the Basilisk peer scripts."""
import math


def attitude_error(a, b):
    """The angle (rad) of the rotation between two attitude quaternions (w, x, y, z), either
    sign: 2 atan2(|v|, |w|) of a* ⊗ b."""
    aw, ax, ay, az = a[0], -a[1], -a[2], -a[3]
    bw, bx, by, bz = b
    w = aw * bw - ax * bx - ay * by - az * bz
    x = aw * bx + ax * bw + ay * bz - az * by
    y = aw * by - ax * bz + ay * bw + az * bx
    z = aw * bz + ax * by - ay * bx + az * bw
    return 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w))
