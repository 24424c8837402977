"""LeRobotDataset v3.0 written and read directly (pyarrow, PyAV): no torch, no lerobot.

The format's facts (paths, info.json keys, the episodes table, statistics) come from LeRobot
0.4.4's ``datasets/utils.py``, ``lerobot_dataset.py``, ``video_utils.py`` and
``compute_stats.py``; docs/learning.md describes the layout. ``writer``, ``reader`` and
``video`` need the ``dataset`` extra; ``layout`` and ``feature_stats`` need numpy only.
"""

from __future__ import annotations
