#!/usr/bin/env python3
"""Reference forward kinematics of the Franka Panda for nesy-sim's FK cross-check.

The reference is roboticstoolbox-python's `models.DH.Panda`, built from Franka's published
modified Denavit-Hartenberg table: a model independent of nesy's URDF. For 50 random arm
configurations within the joint limits (numpy seed 2026) it records the pose of the flange
(link8, i.e. link7 + 0.107 m) relative to the robot base, with the tool transform removed.

Run once in a throwaway virtual environment outside the repository and commit the output:

    python3 -m venv /tmp/fkvenv && /tmp/fkvenv/bin/pip install roboticstoolbox-python
    /tmp/fkvenv/bin/python scripts/fk_reference.py > fixtures/fk/panda_flange_reference.json
"""

import json
import sys

import numpy as np
import roboticstoolbox as rtb
from spatialmath import SE3


def main() -> None:
    panda = rtb.models.DH.Panda()
    panda.tool = SE3()  # the flange itself
    lower, upper = panda.qlim
    rng = np.random.default_rng(2026)
    samples = []
    for _ in range(50):
        q = lower + rng.random(7) * (upper - lower)
        pose = panda.fkine(q).A
        samples.append(
            {
                "q": [float(v) for v in q],
                "position": [float(v) for v in pose[:3, 3]],
                "rotation": [[float(v) for v in row] for row in pose[:3, :3]],
            }
        )
    json.dump(
        {
            "source": "roboticstoolbox-python " + rtb.__version__ + " models.DH.Panda (modified DH), tool removed",
            "frame": "flange (panda_link8) relative to the robot base (panda_link0)",
            "samples": samples,
        },
        sys.stdout,
        indent=1,
    )
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
