"""Reachable space of the simulated Humanoid's left arm: random goals, forearm positions, 3-D plot.

The documentation's "determine the reachable space of the arm" on MuJoCo: random goals within
the left arm's angle limits, the left forearm's position recorded once the arm got there, and
a 3-D scatter plot saved as a PNG.

    .venv/bin/python docs/examples/reachable_space.py            # 150 samples, ~1 minute
    .venv/bin/python docs/examples/reachable_space.py --samples 10 --output /tmp/space.png
"""

from __future__ import annotations

import argparse
import random
import time
from pathlib import Path

from poppy_core import from_profile

ARM = ("l_shoulder_y", "l_shoulder_x", "l_arm_z", "l_elbow_y")
FOREARM = "l_forearm"  # the URDF link; its origin is the elbow
REFERENCE = "chest"  # positions in the chest's frame: the free-standing robot may sway
SETTLE_S = 0.8  # simulated seconds for the arm to reach a goal and stop (MX-28: ~330 °/s)
HERE = Path(__file__).resolve().parent


def wait_simulated(simulation: object, seconds: float) -> None:
    """Sleep until ``seconds`` of simulated time passed (the physics may run faster than real)."""
    data = simulation.data  # type: ignore[attr-defined]
    end = float(data.time) + seconds
    while float(simulation.data.time) < end:  # type: ignore[attr-defined]
        time.sleep(0.005)


def sample(samples: int, seed: int, speed: float) -> list[tuple[float, float, float]]:
    """Forearm positions (m, chest frame) for ``samples`` random left-arm goals."""
    rng = random.Random(seed)
    points = []
    with from_profile("humanoid", sim="mujoco") as robot:
        simulation = robot.simulation
        simulation.speed = speed
        robot.compliant = False  # the servos hold the robot up
        simulation.reset()  # stand up again after the compliant start
        wait_simulated(simulation, 0.5)
        for _ in range(samples):
            goals = {}
            for name in ARM:
                low, high = robot.motor(name).angle_limit
                goals[name] = rng.uniform(low, high)
            for name, goal in goals.items():
                robot.motor(name).goal_position = goal
            wait_simulated(simulation, SETTLE_S)
            x, y, z = simulation.get_object_position(FOREARM, relative_to=REFERENCE)
            points.append((x, y, z))
    return points


def plot(points: list[tuple[float, float, float]], output: Path) -> None:
    """A 3-D scatter of the points, saved as a PNG."""
    import matplotlib

    matplotlib.use("Agg")  # no display needed
    import matplotlib.pyplot as plt

    figure = plt.figure(figsize=(7, 6))
    axes = figure.add_subplot(projection="3d")
    xs, ys, zs = zip(*points, strict=True)
    axes.scatter(xs, ys, zs, c=zs, cmap="viridis", s=14)
    axes.scatter([0], [0], [0], c="red", s=40, marker="x", label=f"{REFERENCE} origin")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_zlabel("z (m)")
    axes.set_title(f"Poppy Humanoid (MuJoCo): left forearm, {len(points)} random goals")
    axes.legend(loc="upper left")
    output.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(output, dpi=100, bbox_inches="tight")
    plt.close(figure)


def main(argv: list[str] | None = None) -> None:
    """Sample, plot, and print where the PNG went."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=150, help="random goals (default 150)")
    parser.add_argument("--seed", type=int, default=1, help="random seed")
    parser.add_argument("--speed", type=float, default=4.0,
                        help="simulated seconds per real second (default 4)")
    parser.add_argument("--output", type=Path, default=HERE / "reachable_space.png")
    args = parser.parse_args(argv)
    points = sample(args.samples, args.seed, args.speed)
    plot(points, args.output)
    print(f"{len(points)} forearm positions plotted in {args.output}")


if __name__ == "__main__":
    main()
