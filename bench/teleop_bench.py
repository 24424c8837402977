"""Teleoperation benchmark: leader read → follower goal latency, rate, tracking, link stalls.

Three setups, every figure measured at the emulators (``bench.teleop_probe``):

1. **Local**: Ergo Jr → Ergo Jr at 100 Hz, two buses (``poppy teleop``'s ``teleoperate``).
2. **Remote**: the follower served by ``poppy serve --http`` in its own process, driven at 50 Hz
   over the WebSocket through a loopback proxy that then stalls the link for 2 s: the server must
   hold the follower within 0.5 s and resume with a ramp.
3. **Torso arm copy**, side by side: one emulated Torso copying its left arm to its right arm,
   with poppy's ``teleoperate`` (the mirror map of ``arms_copy_motion``) at 50 Hz and with
   pypot's own ``arms_copy_motion`` (poppy-torso's ``PuppetMaster``, 50 Hz).
"""

from __future__ import annotations

import logging
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

from bench.clients import PEERS_PYTHON, SETUP_SCRIPT
from bench.link_proxy import LinkProxy
from bench.registry import BENCH_DIR, POPPY_PYTHON, REPO_ROOT, BenchContext, BenchResult, register
from bench.teleop_probe import BusProbe, Hand
from bench.teleop_report import build_result
from bench.teleop_scenarios import (
    Client,
    Durations,
    bus_of,
    measure,
    pairing,
    poppy_server,
    served,
    stall,
)
from poppy_core.motion.teleop.joint_map import JointMap
from poppy_core.robot import load_config, load_profile

logger = logging.getLogger(__name__)

TORSO_JSON = REPO_ROOT / "tests" / "robot" / "data" / "poppy_torso.json"
PYPOT_SCRIPT = BENCH_DIR / "peers" / "pypot_arms_copy.py"
# poppy-torso's PuppetMaster: right goal = left present, negated for indirect left motors.
# The elbows are left out of the hand's moves: l_elbow_y [-140, 0] copied unchanged lands outside
# r_elbow_y's [0, 147] (both from the public poppy_torso.json), so that copy only pins the limit.
ARMS_COPY = "r_shoulder_y=l_shoulder_y, r_shoulder_x=-l_shoulder_x, r_arm_z=-l_arm_z"
RESOLUTION_DEG = {"XL-320": 0.29, "MX-28": 0.088}


def _client(*args: str) -> list[str]:
    return [str(POPPY_PYTHON), "-m", "bench.teleop_client", *args]


class _ErgoPair:
    """Two emulated Ergo Jr buses, the leader moved by a hand, both probed at the wire."""

    def __init__(self) -> None:
        config = load_profile("ergo-jr")
        mapping = JointMap.same_names(list(config.motors), list(config.motors))
        ranges, self.follower_of, self.ids = pairing(config, config, mapping)
        self.leader_bus, self.follower_bus = bus_of(config), bus_of(config)
        self.leader = BusProbe(self.leader_bus, list(self.ids.values()), [])
        follower_ids = [i for i, _ in self.follower_of.values()]
        self.follower = BusProbe(self.follower_bus, [], follower_ids)
        self.hand = Hand({n: self.leader_bus.motor(i) for n, i in self.ids.items()}, ranges)
        self.hand.put(self.hand.now())

    def measure(self, durations: Durations) -> dict[str, Any]:
        """``teleop_scenarios.measure`` on this pair (XL-320s: two steps of resolution)."""
        return measure(
            self.hand,
            self.leader,
            self.follower,
            self.follower_bus,
            self.follower_of,
            self.ids,
            2 * RESOLUTION_DEG["XL-320"],
            durations,
        )


def run_local(durations: Durations, rate_hz: float = 100.0) -> dict[str, Any]:
    """Ergo Jr → Ergo Jr, two buses, ``rate_hz``."""
    pair = _ErgoPair()
    leader_bus, follower_bus = pair.leader_bus, pair.follower_bus
    with served([leader_bus, follower_bus]) as (leader_port, follower_port):
        client = Client(
            _client(
                "--leader-port",
                leader_port,
                "--follower-port",
                follower_port,
                "--rate",
                f"{rate_hz:g}",
            )
        )
        return _run(client, lambda: pair.measure(durations))


def run_remote(durations: Durations, rate_hz: float = 50.0) -> dict[str, Any]:
    """Ergo Jr → Ergo Jr served by ``poppy serve``, over a loopback proxy, ``rate_hz``."""
    pair = _ErgoPair()
    leader_bus, follower_bus = pair.leader_bus, pair.follower_bus
    with (
        served([leader_bus, follower_bus]) as (leader_port, follower_port),
        poppy_server("ergo-jr", follower_port) as url,
    ):
        host, port = url.removeprefix("http://").rsplit(":", 1)
        with LinkProxy(host, int(port)) as proxy:
            client = Client(
                _client(
                    "--leader-port",
                    leader_port,
                    "--follower-url",
                    proxy.url,
                    "--rate",
                    f"{rate_hz:g}",
                )
            )

            def phases() -> dict[str, Any]:
                figures = pair.measure(durations)
                figures["stall"] = stall(pair.hand, proxy, url, pair.follower, durations)
                return figures

            return _run(client, phases)


def run_torso(
    durations: Durations, peer: str, python: Path | None, rate_hz: float = 50.0
) -> dict[str, Any]:
    """One emulated Torso copying its left arm to its right arm (poppy or pypot)."""
    config = load_config(TORSO_JSON)
    mapping = JointMap.parse(ARMS_COPY)
    ranges, follower_of, ids = pairing(config, config, mapping)
    bus = bus_of(config)
    probe = BusProbe(bus, list(ids.values()), [i for i, _ in follower_of.values()])
    hand = Hand({n: bus.motor(i) for n, i in ids.items()}, ranges)
    hand.put(hand.now())
    with served([bus]) as (port,):
        if peer == "pypot":
            assert python is not None
            args = [
                str(python),
                str(PYPOT_SCRIPT),
                "--config",
                str(TORSO_JSON),
                "--port",
                f"upper_body_controller={port}",
            ]
        else:
            args = _client(
                "--profile",
                "torso",
                "--leader-port",
                port,
                "--map",
                ARMS_COPY,
                "--rate",
                f"{rate_hz:g}",
            )
        client = Client(args)
        return _run(
            client,
            lambda: measure(
                hand,
                probe,
                probe,
                bus,
                follower_of,
                ids,
                2 * RESOLUTION_DEG["MX-28"],
                durations,
            ),
        )


def _run(client: Client, phases: Callable[[], dict[str, Any]]) -> dict[str, Any]:
    figures: dict[str, Any] = {}
    try:
        if client.wait_following():
            figures = phases()
    finally:
        record = client.stop()
    if not figures and record.get("error") is None:
        record["error"] = "never followed: " + " | ".join(client.lines[-3:])
    return {"client": record, **figures}


def _pypot_python(ctx: BenchContext) -> tuple[Path | None, str]:
    """The peers venv's python when it can import poppy-torso (installing it if needed)."""
    if ctx.peers_python is None:
        return None, ctx.peers_note
    check = [
        str(PEERS_PYTHON),
        "-c",
        "import pypot.creatures; import poppy_torso.primitives.interaction",
    ]
    if subprocess.run(check, capture_output=True, check=False).returncode != 0:
        subprocess.run(["bash", str(SETUP_SCRIPT), "--force"], capture_output=True, check=False)
        if subprocess.run(check, capture_output=True, check=False).returncode != 0:
            return None, "poppy-torso could not be installed in bench/.venv-peers"
    return ctx.peers_python, ""


@register(
    "teleop",
    "teleoperation: read→goal latency, rate, tracking, link stall; pypot's arms_copy_motion",
)
def teleop_bench(ctx: BenchContext, durations: Durations | None = None) -> BenchResult:
    """Run every setup ``ctx.repeat`` times (see the module docstring)."""
    durations = durations or Durations()
    python, note = _pypot_python(ctx)
    runs: dict[str, list[dict[str, Any]]] = {
        "local": [],
        "remote": [],
        "torso_poppy": [],
        "torso_pypot": [],
    }
    setups: list[tuple[str, str, Callable[[], dict[str, Any]]]] = [
        ("local", "local 100 Hz", lambda: run_local(durations)),
        ("remote", "remote 50 Hz over the WebSocket, link stall", lambda: run_remote(durations)),
        ("torso_poppy", "Torso arm copy, poppy", lambda: run_torso(durations, "poppy", None)),
    ]
    if python is not None:
        setups.append(
            (
                "torso_pypot",
                "Torso arm copy, pypot arms_copy_motion",
                lambda: run_torso(durations, "pypot", python),
            )
        )
    for index in range(ctx.repeat):
        for key, label, run in setups:
            logger.info("teleop: run %d/%d, %s", index + 1, ctx.repeat, label)
            try:
                runs[key].append(run())
            except Exception as exc:  # one failed run is reported, the others still count
                logger.warning("teleop: %s failed: %s", label, exc)
                runs[key].append({"client": {"error": f"{type(exc).__name__}: {exc}"}})
    return build_result(runs, note, durations)
