"""Dataset benchmark: recording at 30 fps with a 640×480 camera and the sync loops at 50 Hz.

poppy (`bench.dataset_client`: an emulated Ergo Jr, `EpisodeRecorder`, the video encoded in
a process of its own) and, in the same run, LeRobot's own writer
(`bench/peers/lerobot_dataset_record.py` in the LeRobot venv:
`LeRobotDataset.create/add_frame/save_episode` with lerobot-record's defaults) record one
episode of the same moving scene for `--minutes` (default 5), one after the other.
"""

from __future__ import annotations

import json
import logging
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from bench.registry import BENCH_DIR, REPO_ROOT, BenchContext, BenchResult, Table, register

logger = logging.getLogger(__name__)

FPS = 30
DEFAULT_MINUTES = 5.0
SYNC_GOAL_HZ = 49.0
PEER_SCRIPT = BENCH_DIR / "peers" / "lerobot_dataset_record.py"


def lerobot_python() -> Path | None:
    """The LeRobot venv's interpreter (``$POPPY_LEROBOT_VENV``, else bench/.venv-lerobot)."""
    for place in (os.environ.get("POPPY_LEROBOT_VENV"), str(BENCH_DIR / ".venv-lerobot")):
        if place and (Path(place) / ".installed").is_file():
            return Path(place) / "bin" / "python"
    return None


def _load() -> float:
    return os.getloadavg()[0]


def _run(argv: list[str], env: dict[str, str], timeout_s: float) -> dict[str, Any]:
    before = _load()
    done = subprocess.run(
        argv, capture_output=True, text=True, timeout=timeout_s, env=env, cwd=REPO_ROOT, check=False
    )
    if done.returncode != 0:
        raise RuntimeError(f"{argv[1]} failed ({done.returncode}): {done.stderr[-2000:]}")
    figures: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    figures["load_before"], figures["load_after"] = before, _load()
    return figures


def measure(minutes: float) -> dict[str, Any]:
    """Both writers, one after the other, each in a fresh temporary folder (removed after)."""
    seconds = 60.0 * minutes
    timeout_s = 4 * seconds + 600
    results: dict[str, Any] = {"minutes": minutes, "fps": FPS}
    with tempfile.TemporaryDirectory(prefix="poppy-bench-dataset-") as folder:
        env = dict(os.environ, PYTHONPATH=str(REPO_ROOT))
        logger.info("poppy: %g min at %d fps", minutes, FPS)
        argv = [sys.executable, "-m", "bench.dataset_client", f"{folder}/poppy", f"{seconds}"]
        results["poppy"] = _run([*argv, str(FPS)], env, timeout_s)
        shutil.rmtree(f"{folder}/poppy")
        peer = lerobot_python()
        if peer is None:
            results["lerobot"] = None
            results["lerobot_note"] = "LeRobot's venv is missing: run bench/setup_lerobot.sh"
            return results
        logger.info("LeRobot 0.4.4: %g min at %d fps", minutes, FPS)
        peer_env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        peer_env.update(HF_HUB_OFFLINE="1", HF_DATASETS_CACHE=f"{folder}/hf-cache")
        argv = [str(peer), str(PEER_SCRIPT), f"{folder}/lerobot", f"{seconds}", str(FPS)]
        results["lerobot"] = _run(argv, peer_env, timeout_s)
    return results


def _row(name: str, figures: dict[str, Any], minutes: float) -> list[str]:
    seconds = 60.0 * minutes
    wall_s = figures["loop_s"] + figures["save_s"]
    sync = (
        f"{figures['sync_hz_min']:.1f} / {figures['sync_hz_median']:.1f}"
        if figures.get("sync_hz_min") is not None
        else "- (no robot)"
    )
    dropped_video = figures.get("video_dropped")
    return [
        name,
        f"{figures['frames']} of {round(seconds * FPS)}",
        f"{figures['frames'] / figures['loop_s']:.2f}",
        str(figures["missed_ticks"]),
        "-" if dropped_video is None else str(dropped_video),
        sync,
        f"{figures['save_s']:.1f}",
        f"{100 * figures['cpu_s'] / wall_s:.0f} %",
        f"{figures['max_rss_mb']:.0f}"
        + (f" + {figures['encoder_max_rss_mb']:.0f}" if "encoder_max_rss_mb" in figures else ""),
        (
            f"{figures['rss_first_mb']:.0f} → {figures['rss_last_mb']:.0f}"
            if figures.get("rss_first_mb") is not None
            else "-"
        ),
        f"{figures['bytes'] / 1e6 / minutes:.1f}",
        f"{figures['load_before']:.1f} → {figures['load_after']:.1f}",
    ]


@register(
    "dataset",
    "recording a LeRobot dataset: 30 fps, a 640×480 camera, sync loops at 50 Hz; LeRobot beside",
    long=True,
)
def run(ctx: BenchContext) -> BenchResult:
    """Measure poppy's recording and LeRobot's writer on the same load, one after the other."""
    minutes = ctx.minutes or DEFAULT_MINUTES
    raw = measure(minutes)
    poppy = raw["poppy"]
    rows = [_row("poppy (this checkout)", poppy, minutes)]
    if raw["lerobot"] is not None:
        rows.append(_row("LeRobot 0.4.4 (its writer)", raw["lerobot"], minutes))
    held = poppy["missed_ticks"] == 0 and poppy["video_dropped"] == 0
    passed = held and (poppy["sync_hz_min"] or 0) >= SYNC_GOAL_HZ
    notes = [
        f"Goals (issue 37): no dropped frame, the sync loops at ≥ {SYNC_GOAL_HZ:g} Hz, the video "
        "encoded in another process, memory bounded. poppy's video is encoded by a process of "
        f"its own ({poppy['codec']}, LeRobot's settings) fed through a ring of one second of "
        'frames in shared memory; a frame the ring cannot take is dropped, counted ("video '
        'frames dropped") and stood in for by the last one, so the video keeps a frame a row. '
        '"Missed ticks" are 1/30 s ticks the recording loop was too late for (no row).',
        "LeRobot drives no Poppy servo: its run has no robot and no sync loop, six joints of "
        "synthetic state, and the same scene's frames; lerobot-record's defaults (PNG files "
        "written by 4 threads, the video encoded by save_episode after the episode, libsvtav1). "
        '"After the episode" is the time from the episode\'s end until its files are written.',
        "CPU: user + system time of the process and its children over the episode and its save, "
        "as a share of one core. Peak memory: the recorder's peak RSS (+ the encoder process's, "
        "for poppy); poppy's RSS is sampled every 2 s of the episode: its first and last samples "
        "show whether memory grows with the episode's length. The load (1-minute average, "
        "before → after) is the shared machine's: figures taken on a loaded machine say little "
        "about an idle one.",
        "poppy's RSS grows while its ring (one second of frames: 27.6 MB at 640×480 and 30 fps) "
        "is touched page by page in its first second; past that it holds the episode's state "
        "and action rows (a few hundred bytes a frame). LeRobot keeps the episode's buffer and "
        "writes a PNG a frame before encoding the video after the episode.",
    ]
    if raw["lerobot"] is None:
        notes.append(str(raw["lerobot_note"]))
    table = Table(
        f"One episode of {minutes:g} min at {FPS} fps, one 640×480 camera",
        [
            "writer",
            "frames",
            "fps held",
            "missed ticks",
            "video frames dropped",
            "sync loops Hz (min / median)",
            "after the episode (s)",
            "CPU",
            "peak RSS (MB)",
            "RSS first → last sample (MB)",
            "MB per minute",
            "load",
        ],
        rows,
    )
    return BenchResult(
        name="dataset",
        title="Dataset recording (LeRobot v3.0)",
        intro=__doc__.split("\n\n", 1)[1].replace("\n", " ").strip() if __doc__ else "",
        tables=[table],
        notes=notes,
        passed=passed,
        raw=raw,
    )
