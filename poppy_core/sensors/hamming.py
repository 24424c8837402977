"""Hamming markers: the 9×9 codes of pypot's marker detector (the ``hampy`` library).

Facts of the format, read from hampy 1.4.2 (``hampy/hamming.py``, ``hampy/detect.py``; the
library pypot 5.0.2's ``MarkerDetector`` uses), the code written here: a square of 9×9 cells,
a border ring and a 7×7 code inside. Each of the 7 code rows is a Hamming(7,4) codeword (bits
p1 p2 d1 p3 d2 d3 d4, a bright cell is 1), whose data bits make 4 bits of a 28-bit id, first
row first, most significant bit first. The marker is read in its four rotations; each rotation
that decodes gives an id, as hampy does. The Poppy Education cards carry such codes.
"""

from __future__ import annotations

import numpy as np

GRID = 9
CODE = 7
MAX_ID = 2 ** (CODE * 4)
_DATA = (2, 4, 5, 6)  # positions of d1..d4 in a codeword
# parity checks: a codeword c is valid when H @ c = 0 (mod 2)
_H = np.array([[0, 0, 0, 1, 1, 1, 1], [0, 1, 1, 0, 0, 1, 1], [1, 0, 1, 0, 1, 0, 1]])
# generator: c = G @ d (mod 2)
_G = np.array(
    [
        [1, 1, 0, 1],
        [1, 0, 1, 1],
        [1, 0, 0, 0],
        [0, 1, 1, 1],
        [0, 1, 0, 0],
        [0, 0, 1, 0],
        [0, 0, 0, 1],
    ]
)


def encode(marker_id: int) -> np.ndarray:
    """The 7×7 code (1 = bright) of ``marker_id``.

    Raises:
        ValueError: the id is outside 0 to 2**28 - 1.
    """
    if not 0 <= marker_id < MAX_ID:
        raise ValueError(f"a Hamming marker id is in 0-{MAX_ID - 1}, got {marker_id}")
    bits = np.array([int(b) for b in format(marker_id, f"0{CODE * 4}b")]).reshape(CODE, 4)
    code: np.ndarray = (bits @ _G.T) % 2
    return code


def decode(code: np.ndarray) -> int | None:
    """The id a 7×7 code (1 = bright) carries in this orientation, or None if a row is invalid."""
    if code.shape != (CODE, CODE) or not code.any() or code.all():
        return None
    if ((code @ _H.T) % 2).any():
        return None
    data = code[:, _DATA].ravel()
    return int("".join(str(int(b)) for b in data), 2)


def decode_rotations(code: np.ndarray) -> list[int]:
    """Every id the code gives in its four rotations (hampy reports each), without repeats."""
    found: list[int] = []
    for turn in range(4):
        marker_id = decode(np.rot90(code, turn))
        if marker_id is not None and marker_id not in found:
            found.append(marker_id)
    return found


def image(marker_id: int, cell_px: int = 20, quiet_cells: int = 1) -> np.ndarray:
    """A printable grey image of the marker: black border ring, code, a white margin around.

    Returns:
        ``uint8`` array of ``(GRID + 2 * quiet_cells) * cell_px`` pixels a side.
    """
    grid = np.zeros((GRID, GRID), dtype=np.uint8)
    grid[1:-1, 1:-1] = encode(marker_id)
    grid = np.pad(grid, quiet_cells, constant_values=1)
    return np.kron(grid * 255, np.ones((cell_px, cell_px), dtype=np.uint8)).astype(np.uint8)


def read_cells(square: np.ndarray) -> np.ndarray:
    """The 7×7 code of a marker warped to a square grey image (a multiple of 9 pixels a side).

    Cells are thresholded at the middle of the darkest and brightest cell means.
    """
    size = square.shape[0] // GRID
    cells = square[: size * GRID, : size * GRID].reshape(GRID, size, GRID, size)
    # the middle half of each cell: edges blur in a warped image
    margin = size // 4
    means = cells[:, margin : size - margin, :, margin : size - margin].mean(axis=(1, 3))
    low, high = float(means.min()), float(means.max())
    if high - low < 40:  # no contrast: not a marker
        return np.zeros((CODE, CODE), dtype=np.int64)
    bits: np.ndarray = (means > (low + high) / 2).astype(np.int64)
    return bits[1:-1, 1:-1]
