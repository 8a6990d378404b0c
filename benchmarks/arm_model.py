"""The N-joint arms of the joint-count scale curve: ``model/arm<N>.xml``.

    python -m benchmarks.arm_model            # writes model/arm6.xml, arm12.xml, arm24.xml, arm48.xml
    python -m benchmarks.arm_model --check    # exit status 1 if a file differs from what this writes

Each arm is the same chain: a fixed base and N capsule links 0.08 m long,
hinges alternating about Y and Z, each with a torque motor; only the number
of links differs, so the curve shows how cost grows with joints alone.
Collisions are off (``contype="0"``): the arm never touches itself, so the
physics cost grows with the chain, not with contacts.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
JOINT_COUNTS = (6, 12, 24, 48)
LINK_LENGTH = 0.08  # m


def arm_xml(joints: int) -> str:
    """The MJCF text of an arm with ``joints`` hinge joints ``J01``... and motors of the same names."""
    width = max(2, len(str(joints)))
    lines = [
        "<!--",
        f"  Arm{joints}: a {joints}-joint arm for the scale benchmark (benchmarks/run.py): a fixed",
        f"  base and {joints} capsule links, hinges alternating about Y and Z, each with a",
        "  torque motor.  Armature 0.1 kg*m^2 (the gearboxes) keeps a 30 N*m*s/rad",
        "  explicit damping term stable at the 1 ms step.",
        "  Written by python -m benchmarks.arm_model: edit that, not this file.",
        "-->",
        f'<mujoco model="Arm{joints}">',
        '  <compiler angle="degree" autolimits="true"/>',
        "  <default>",
        '    <joint type="hinge" range="-60 60" armature="0.1" damping="0.5"/>',
        '    <geom type="capsule" size="0.02" rgba="0.25 0.45 0.75 1" mass="0.2" contype="0" conaffinity="0"/>',
        "  </default>",
        "  <worldbody>",
        '    <geom name="base" type="cylinder" size="0.12 0.05" pos="0 0 0.05" rgba="0.3 0.3 0.3 1" mass="5"/>',
    ]
    for k in range(1, joints + 1):
        indent = "  " * (k + 1)
        pos = "0 0 0.1" if k == 1 else f"0 0 {LINK_LENGTH:g}"
        axis = "0 1 0" if k % 2 else "0 0 1"
        lines += [
            f'{indent}<body name="L{k}" pos="{pos}">',
            f'{indent}  <joint name="J{k:0{width}d}" axis="{axis}"/>',
            f'{indent}  <geom fromto="0 0 0 0 0 {LINK_LENGTH:g}"/>',
        ]
    for k in range(joints, 0, -1):
        lines.append("  " * (k + 1) + "</body>")
    lines += ["  </worldbody>", "  <actuator>"]
    lines += [f'    <motor name="J{k:0{width}d}" joint="J{k:0{width}d}"/>' for k in range(1, joints + 1)]
    lines += ["  </actuator>", "</mujoco>", ""]
    return "\n".join(lines)


def model_path(joints: int) -> Path:
    return ROOT / "model" / f"arm{joints}.xml"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="only compare the files with what would be written")
    args = p.parse_args(argv)
    stale = []
    for n in JOINT_COUNTS:
        path, text = model_path(n), arm_xml(n)
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(str(path))
        else:
            path.write_text(text)
            print(f"wrote {path}")
    if stale:
        print("out of date (run python -m benchmarks.arm_model): " + ", ".join(stale))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
