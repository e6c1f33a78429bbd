"""Helpers shared by the peer scripts: an attitude error and the results files' JSON layout."""
import json
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


def compact_json(v, pad=""):
    """JSON indented by structure, with lists of numbers and each sample on one line."""
    inner = pad + " "
    if isinstance(v, dict):
        if not v:
            return "{}"
        if "t" in v and "omega" in v:
            return json.dumps(v)
        items = [f"{inner}{json.dumps(k)}: {compact_json(x, inner)}" for k, x in v.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(v, list) and any(isinstance(x, (dict, list)) for x in v) and v:
        if all(isinstance(x, list) and not any(isinstance(y, (dict, list)) for y in x) for x in v):
            return json.dumps(v)
        return "[\n" + ",\n".join(inner + compact_json(x, inner) for x in v) + "\n" + pad + "]"
    return json.dumps(v)
