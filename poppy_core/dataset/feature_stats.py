"""Statistics of a feature, per episode and over the dataset, as LeRobot keeps them.

Facts from LeRobot 0.4.4's ``compute_stats.py``: min, max, mean, std, count and the quantiles
q01, q10, q50, q90, q99; vectors per element; images per channel, scaled to [0, 1], shaped
(3, 1, 1), on frames downsampled to about 150 pixels when larger than 300; episodes merged by
count-weighted means and the parallel variance formula, quantiles as count-weighted means.
Here quantiles of a vector are exact (numpy's), and an image's come from an exact 256-bin
histogram of every frame, where LeRobot samples frames.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)
QUANTILE_KEYS = tuple(f"q{round(q * 100):02d}" for q in QUANTILES)
Stats = dict[str, NDArray[Any]]
"""Statistic name -> value; min and max keep an integer feature's integers, count is an integer."""


def vector_stats(values: NDArray[Any]) -> Stats:
    """Stats of ``values`` (frames x elements, or frames) along the frames."""
    raw = np.asarray(values)
    if raw.ndim == 1:
        raw = raw.reshape(-1, 1)
    data = raw.astype(np.float64)
    stats: Stats = {
        "min": raw.min(axis=0),
        "max": raw.max(axis=0),
        "mean": data.mean(axis=0),
        "std": data.std(axis=0),
        "count": np.array([raw.shape[0]], dtype=np.int64),
    }
    for key, q in zip(QUANTILE_KEYS, QUANTILES, strict=True):
        stats[key] = np.quantile(data, q, axis=0)
    return stats


def downsample(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """LeRobot's ``auto_downsample_height_width`` on a height x width x 3 frame."""
    height, width = frame.shape[:2]
    if max(width, height) < 300:
        return frame
    step = int(width / 150) if width > height else int(height / 150)
    return frame[::step, ::step]


class ImageStats:
    """Per-channel statistics of a camera's frames, gathered frame by frame in bounded memory."""

    def __init__(self) -> None:
        self.frames = 0
        self.pixels = 0
        self.histogram = np.zeros((3, 256), dtype=np.int64)

    def add(self, frame: NDArray[np.uint8]) -> None:
        """Count one height x width x 3 RGB frame."""
        small = downsample(frame).reshape(-1, 3)
        for channel in range(3):
            self.histogram[channel] += np.bincount(small[:, channel], minlength=256)
        self.frames += 1
        self.pixels += small.shape[0]

    def result(self) -> Stats:
        """min, max, mean, std, quantiles in [0, 1] shaped (3, 1, 1); count: frames."""
        levels = np.arange(256, dtype=np.float64)
        hist = self.histogram.astype(np.float64)
        total = hist.sum(axis=1)
        mean = (hist * levels).sum(axis=1) / total
        var = (hist * (levels - mean[:, None]) ** 2).sum(axis=1) / total
        present = hist > 0
        low = np.array([levels[row].min() for row in present])
        high = np.array([levels[row].max() for row in present])
        stats: Stats = {
            "min": low,
            "max": high,
            "mean": mean,
            "std": np.sqrt(var),
            "count": np.array([self.frames], dtype=np.int64),
        }
        cumulative = np.cumsum(hist, axis=1)
        for key, q in zip(QUANTILE_KEYS, QUANTILES, strict=True):
            stats[key] = np.array(
                [_quantile_of_histogram(cumulative[c], q) for c in range(3)], dtype=np.float64
            )
        return {
            key: value if key == "count" else (value / 255.0).reshape(3, 1, 1)
            for key, value in stats.items()
        }


def _quantile_of_histogram(cumulative: NDArray[np.float64], q: float) -> float:
    """numpy's linear quantile of integer samples 0..255 given their cumulative counts."""
    total = cumulative[-1]
    position = q * (total - 1)
    below = int(np.floor(position))
    low = float(np.searchsorted(cumulative, below + 1))
    high = float(np.searchsorted(cumulative, below + 2)) if below + 1 < total else low
    return float(low + (high - low) * (position - below))


def aggregate(stats: list[Stats]) -> Stats:
    """One feature's stats over several episodes (LeRobot's ``aggregate_feature_stats``)."""
    means = np.stack([s["mean"] for s in stats])
    variances = np.stack([s["std"] ** 2 for s in stats])
    counts = np.stack([s["count"] for s in stats])
    total = counts.sum(axis=0)
    while counts.ndim < means.ndim:
        counts = np.expand_dims(counts, axis=-1)
    mean = (means * counts).sum(axis=0) / total
    variance = ((variances + (means - mean) ** 2) * counts).sum(axis=0) / total
    merged: Stats = {
        "min": np.min(np.stack([s["min"] for s in stats]), axis=0),
        "max": np.max(np.stack([s["max"] for s in stats]), axis=0),
        "mean": mean,
        "std": np.sqrt(variance),
        "count": total,
    }
    for key in QUANTILE_KEYS:
        merged[key] = (np.stack([s[key] for s in stats]) * counts).sum(axis=0) / total
    return merged


def aggregate_all(episodes: list[dict[str, Stats]]) -> dict[str, Stats]:
    """Every feature's stats over the episodes that have them."""
    keys = list(dict.fromkeys(key for episode in episodes for key in episode))
    return {key: aggregate([e[key] for e in episodes if key in e]) for key in keys}


def to_json(stats: dict[str, Stats]) -> dict[str, dict[str, Any]]:
    """stats.json's shape: lists of numbers."""
    return {key: {name: value.tolist() for name, value in f.items()} for key, f in stats.items()}


def from_json(data: dict[str, dict[str, Any]]) -> dict[str, Stats]:
    """stats.json read back as arrays."""
    return {
        key: {name: np.asarray(value) for name, value in feature.items()}
        for key, feature in data.items()
    }
