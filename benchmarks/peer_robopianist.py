"""Env steps/s of the peer RoboPianist (MuJoCo, two Shadow hands, 88 keys), random actions.

Run by benchmarks/sim.py with the Python of an environment where robopianist is installed
(it needs Debian's portaudio19-dev, and mujoco 3.3.2 matching dm_control 1.0.30). Prints one
number per repeat.
"""

import sys
import time

import numpy as np
from robopianist import suite

steps, repeats = int(sys.argv[1]), int(sys.argv[2])
env = suite.load("RoboPianist-debug-TwinkleTwinkleRousseau-v0")
spec = env.action_spec()
rng = np.random.default_rng(0)
env.reset()
for _ in range(repeats):
    start = time.perf_counter()
    for _ in range(steps):
        if env.step(rng.uniform(spec.minimum, spec.maximum, spec.shape)).last():
            env.reset()
    print(steps / (time.perf_counter() - start), flush=True)
