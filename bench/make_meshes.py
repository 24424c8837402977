"""Make the profiles' decimated visual meshes (profiles/<robot>/meshes/) once, offline.

Run by a developer, with the three public repositories as git directories (a clone or a mirror)::

    python -m bench.make_meshes --humanoid DIR --torso DIR --ergo-jr DIR [--profiles profiles]

It needs ``fast-simplification`` and ``scipy`` (the ``meshes`` extra; nothing at run time uses
them). The meshes are the Poppy project's hardware, CC BY-SA 4.0: each
profiles/<robot>/meshes/LICENSE names the source commits.

- Humanoid, Torso: the URDF's visual meshes (``hardware/URDF/meshes/*_visual.STL``), already in
  each link's frame and in metres; the Torso's files but its base are the Humanoid's (the same
  blobs, stored as Git LFS pointers in poppy-torso, so they are read from poppy-humanoid).
- Ergo Jr: the URDF names one mesh per link (``base_link.STL`` ... ``tip.STL``), Git LFS pointers
  in its repository; the parts (XL-320 body and horns, the printed U and side parts, base, lamp
  head, in mm) are real files at commit 3a310900 (``simulator/js/ergo/stl/binary/``). Each link's
  mesh gathers the parts its segment held in that browser simulator's assembly (the offsets and
  turns below are facts of ``simulator/js/ergo/ergojr.js``, ``XL320.js`` and ``ollo.js`` there),
  carried into the URDF's frames by a fixed turn (the simulator's y up is the URDF's z up) and a
  1.8 mm lift, which put every motor axis of the assembly on the URDF's joint axis (the tool
  prints the largest distance).
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

HUMANOID_MESHES = "hardware/URDF/meshes"
ERGO_COMMIT = "3a310900"
ERGO_PARTS = "simulator/js/ergo/stl/binary"
ROBOT_URDF = {
    "humanoid": "poppy_humanoid.urdf",
    "torso": "poppy_torso.urdf",
    "ergo-jr": "poppy_ergo_jr.urdf",
}
# The share of triangles kept, per robot: the budget (see docs/simulation.md, "Meshes").
KEEP = {"humanoid": 0.18, "torso": 0.18, "ergo-jr": 0.35}
MIN_TRIANGLES = 200


def git_blob(repo: Path, rev: str, path: str) -> bytes:
    """The bytes of ``path`` at ``rev`` in the git directory ``repo``."""
    return subprocess.run(
        ["git", f"--git-dir={repo}", "show", f"{rev}:{path}"], check=True, capture_output=True
    ).stdout


def git_head(repo: Path, rev: str = "HEAD") -> str:
    out = subprocess.run(
        ["git", f"--git-dir={repo}", "rev-parse", rev], check=True, capture_output=True, text=True
    )
    return out.stdout.strip()


def read_stl(data: bytes) -> Array:
    """Triangles (n, 3, 3) of a binary STL file."""
    if data.startswith(b"version https://git-lfs"):
        raise ValueError("a Git LFS pointer, not an STL file")
    count = int(np.frombuffer(data[80:84], "<u4")[0])
    if 84 + 50 * count != len(data):
        raise ValueError("not a binary STL file")
    record = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])
    return np.frombuffer(data[84:], record)["vertices"].astype(np.float64)


def write_stl(path: Path, triangles: Array, header: str) -> None:
    """Write ``triangles`` (n, 3, 3) as a binary STL with facet normals."""
    record = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])
    out = np.zeros(len(triangles), record)
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    out["normal"] = normals / np.where(length > 0, length, 1.0)
    out["vertices"] = triangles
    head = header.encode("ascii")[:80].ljust(80, b" ")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(head + np.uint32(len(triangles)).tobytes() + out.tobytes())


def weld(triangles: Array) -> tuple[Array, NDArray[np.int64]]:
    """Shared vertices and faces of a triangle soup (closer than 1e-6 of its size: merged)."""
    flat = triangles.reshape(-1, 3)
    scale = float(np.ptp(flat, axis=0).max()) or 1.0
    keys = np.round(flat / (scale * 1e-6)).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    faces = inverse.reshape(-1, 3)
    good = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    return flat[first], faces[good]


def decimate(triangles: Array, keep: float) -> Array:
    """About ``keep`` of the triangles, by quadric edge collapse (fast-simplification)."""
    import fast_simplification

    points, faces = weld(triangles)
    target = max(MIN_TRIANGLES, int(len(faces) * keep))
    if target >= len(faces):
        return points[faces]
    new_points, new_faces = fast_simplification.simplify(
        points.astype(np.float32),
        faces.astype(np.int32),
        target_reduction=1.0 - target / len(faces),
    )
    return np.asarray(new_points, np.float64)[np.asarray(new_faces)]


def surface_samples(triangles: Array, count: int, seed: int = 0) -> Array:
    """``count`` points spread over the surface by area."""
    rng = np.random.default_rng(seed)
    area = np.linalg.norm(
        np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]), axis=1
    )
    pick = rng.choice(len(triangles), count, p=area / area.sum())
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = triangles[pick]
    return t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])


def deviation_mm(original: Array, decimated: Array) -> float:
    """The 99th percentile distance (mm) from the original surface to the decimated one."""
    from scipy.spatial import cKDTree

    tree = cKDTree(surface_samples(decimated, 60000, 1))
    distance, _ = tree.query(surface_samples(original, 6000))
    return float(np.percentile(distance, 99) * 1000.0)


# The Ergo Jr's assembly: facts of the 2015 browser simulator (mm, three.js Euler XYZ turns).
MOTOR_HEIGHT, MOTOR_WIDTH, MOTOR_LENGTH, AXIS_OFFSET = 24.0, 24.0, 36.0, 9.0
LAYER, SPACING = 3.0, 6.0
U_HORN_TO_HORN, SHIFT_ONE_SIDE = 25.0, 30.0
U_SIDE_TO_HORN = SPACING / 2 + LAYER
HALF_PI = math.pi / 2


def _rot(ax: float, ay: float, az: float) -> Array:
    cx, sx, cy, sy, cz, sz = (
        math.cos(ax),
        math.sin(ax),
        math.cos(ay),
        math.sin(ay),
        math.cos(az),
        math.sin(az),
    )
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rx @ ry @ rz


def tf(
    pos: tuple[float, float, float] = (0, 0, 0), rot: tuple[float, float, float] = (0, 0, 0)
) -> Array:
    """A 4x4 transform: translate ``pos`` after turning by the Euler angles ``rot`` (XYZ)."""
    m = np.eye(4)
    m[:3, :3] = _rot(*rot)
    m[:3, 3] = pos
    return m


def _xl320(two_horns: bool) -> list[tuple[str, Array]]:
    parts = [("XL320_body", tf()), ("XL320_top_horn", tf((0, 0, MOTOR_HEIGHT / 2 + LAYER / 2)))]
    if two_horns:
        parts.append(("XL320_bottom_horn", tf((0, 0, -MOTOR_HEIGHT / 2 - LAYER / 2))))
    return parts


def _side_to_side(frame: Array) -> list[tuple[str, Array]]:
    left = tf((0, 0, -MOTOR_WIDTH / 2 - LAYER / 2))
    right = tf((0, 0, MOTOR_WIDTH / 2 + LAYER / 2), (0, math.pi, 0))
    return [("shift_one_side", frame @ left), ("shift_one_side", frame @ right)]


def ergo_segments() -> dict[str, tuple[Array, list[tuple[str, Array]]]]:
    """URDF link -> (its segment's frame in the simulator's world, parts placed in that frame)."""
    s0 = tf((0, MOTOR_HEIGHT / 2 + LAYER, 0), (-HALF_PI, 0, 0))
    s1 = s0 @ tf((0, 0, MOTOR_HEIGHT / 2 + LAYER))
    s2 = s1 @ tf((0, 0, U_HORN_TO_HORN), (-HALF_PI, -HALF_PI, 0))
    side_y = -MOTOR_LENGTH + AXIS_OFFSET + SPACING / 2
    s3 = s2 @ tf((0, side_y - SHIFT_ONE_SIDE, 0))
    s4 = s3 @ tf(
        (0, -MOTOR_LENGTH + AXIS_OFFSET - MOTOR_HEIGHT / 2 - U_SIDE_TO_HORN, 0),
        (-HALF_PI, 0, HALF_PI),
    )
    s5 = s4 @ tf((0, -3 * SPACING - SHIFT_ONE_SIDE, 0), (0, -HALF_PI, 0))
    s6 = s5 @ tf((0, -4 * SPACING - SHIFT_ONE_SIDE, 0))
    return {
        "base_link": (s0, [("base", tf()), *_xl320(False)]),
        "long_U": (s1, [("U_horn_to_horn", tf((0, 0, U_HORN_TO_HORN), (-HALF_PI, -HALF_PI, 0)))]),
        "section_1": (s2, [*_xl320(True), *_side_to_side(tf((0, side_y, 0), (0, 0, math.pi)))]),
        "section_2": (
            s3,
            [*_xl320(True), ("U_side_to_horn", tf((0, side_y, 0), (math.pi, HALF_PI, 0)))],
        ),
        "section_3": (
            s4,
            [*_xl320(False), *_side_to_side(tf((0, -3 * SPACING, 0), (math.pi, HALF_PI, 0)))],
        ),
        "section_4": (
            s5,
            [*_xl320(True), *_side_to_side(tf((0, -4 * SPACING, 0), (math.pi, 0, 0)))],
        ),
        "tip": (
            s6,
            [*_xl320(True), ("lamp_head", tf((0, -4 * SPACING, 0), (math.pi, HALF_PI, 0)))],
        ),
    }


# The simulator's world (mm, y up, the arm leaning to -z) -> the URDF's (mm, z up, leaning to -y):
# (x, y, z) -> (-x, z, y), lifted 1.8 mm.
SIM_TO_URDF = tf((0, 0, 1.8)) @ tf(rot=(0, 0, math.pi)) @ tf(rot=(HALF_PI, 0, 0))


def _rpy(r: float, p: float, y: float) -> Array:
    return _rot(0, 0, y) @ _rot(0, p, 0) @ _rot(r, 0, 0)


@dataclass(frozen=True)
class UrdfLink:
    """A link's frame at the zero posture (mm), its joint's axis in the world and its mesh file."""

    frame: Array
    axis: Array | None
    mesh: str | None


def urdf_links(path: Path) -> dict[str, UrdfLink]:
    """Every link's world frame at the zero posture (translation in mm) and its visual mesh file."""
    root = ET.parse(path).getroot()
    frames: dict[str, Array] = {}
    axes: dict[str, Array] = {}
    joints = root.findall("joint")
    children = {j.find("child").get("link") for j in joints}  # type: ignore[union-attr]
    for link in root.findall("link"):
        if link.get("name") not in children:
            frames[str(link.get("name"))] = np.eye(4)
    pending = list(joints)
    while pending:
        for joint in list(pending):
            parent = str(joint.find("parent").get("link"))  # type: ignore[union-attr]
            if parent not in frames:
                continue
            child = str(joint.find("child").get("link"))  # type: ignore[union-attr]
            origin = joint.find("origin")
            xyz = [float(x) * 1000 for x in (origin.get("xyz") or "0 0 0").split()]  # type: ignore[union-attr]
            rpy = [float(x) for x in (origin.get("rpy") or "0 0 0").split()]  # type: ignore[union-attr]
            local = np.eye(4)
            local[:3, :3] = _rpy(*rpy)
            local[:3, 3] = xyz
            frames[child] = frames[parent] @ local
            axis = joint.find("axis")
            if axis is not None:
                axes[child] = frames[child][:3, :3] @ np.array(
                    [float(x) for x in str(axis.get("xyz")).split()]
                )
            pending.remove(joint)
    links: dict[str, UrdfLink] = {}
    for link in root.findall("link"):
        name = str(link.get("name"))
        mesh = link.find("visual/geometry/mesh")
        file = str(mesh.get("filename")).rsplit("/", 1)[-1] if mesh is not None else None
        links[name] = UrdfLink(frames[name], axes.get(name), file)
    return links


def ergo_link_triangles(repo: Path, links: dict[str, UrdfLink]) -> dict[str, Array]:
    """Each Ergo Jr link's parts, in the link's URDF frame, in metres."""
    cache: dict[str, Array] = {}
    result: dict[str, Array] = {}
    for link, (segment, parts) in ergo_segments().items():
        to_link = np.linalg.inv(links[link].frame) @ SIM_TO_URDF @ segment
        pieces = []
        for name, placement in parts:
            if name not in cache:
                cache[name] = read_stl(git_blob(repo, ERGO_COMMIT, f"{ERGO_PARTS}/{name}.stl"))
            m = to_link @ placement
            pieces.append(cache[name] @ m[:3, :3].T + m[:3, 3])
        result[link] = np.concatenate(pieces) / 1000.0
    return result


def check_ergo_axes(links: dict[str, UrdfLink]) -> float:
    """The largest distance (mm) from an assembly's motor axis to its URDF joint axis."""
    worst = 0.0
    for link, (segment, _) in ergo_segments().items():
        axis = links[link].axis
        if axis is None:
            continue
        world = SIM_TO_URDF @ segment
        sim_axis = world[:3, 2]
        if abs(abs(float(sim_axis @ axis)) - 1.0) > 1e-6:
            raise ValueError(f"{link}: the assembly's motor axis is not the URDF's")
        offset = world[:3, 3] - links[link].frame[:3, 3]
        worst = max(worst, float(np.linalg.norm(offset - (offset @ axis) * axis)))
    return worst


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--humanoid", type=Path, required=True, help="poppy-humanoid git directory")
    parser.add_argument("--torso", type=Path, required=True, help="poppy-torso git directory")
    parser.add_argument("--ergo-jr", type=Path, required=True, help="poppy-ergo-jr git directory")
    parser.add_argument("--profiles", type=Path, default=Path("profiles"))
    args = parser.parse_args(argv)
    ergo_links = urdf_links(args.profiles / "ergo-jr" / ROBOT_URDF["ergo-jr"])
    print(f"Ergo Jr assembly: motor axes within {check_ergo_axes(ergo_links):.2f} mm of the URDF's")
    total_before = total_after = 0
    for robot, urdf in ROBOT_URDF.items():
        links = urdf_links(args.profiles / robot / urdf)
        if robot == "ergo-jr":
            source = {
                str(links[link].mesh): tris
                for link, tris in ergo_link_triangles(args.ergo_jr, links).items()
            }
            origin = f"poppy-ergo-jr@{git_head(args.ergo_jr, ERGO_COMMIT)[:10]}"
        else:
            source = {}
            for link in links.values():
                if link.mesh is None:
                    continue
                try:
                    data = git_blob(args.humanoid, "HEAD", f"{HUMANOID_MESHES}/{link.mesh}")
                except subprocess.CalledProcessError:
                    data = git_blob(args.torso, "HEAD", f"{HUMANOID_MESHES}/{link.mesh}")
                source[link.mesh] = read_stl(data)
            origin = f"poppy-humanoid@{git_head(args.humanoid)[:10]}"
        before = after = 0
        worst = 0.0
        for file, tris in sorted(source.items()):
            small = decimate(tris, KEEP[robot])
            out = args.profiles / robot / "meshes" / file
            write_stl(out, small, f"poppy: {file} from {origin}, decimated, CC BY-SA 4.0")
            dev = deviation_mm(tris, small)
            worst = max(worst, dev)
            before += len(tris)
            after += len(small)
            print(
                f"  {robot}/{file}: {len(tris)} -> {len(small)} triangles, 99% within {dev:.2f} mm"
            )
        size = sum(p.stat().st_size for p in (args.profiles / robot / "meshes").glob("*.STL"))
        print(
            f"{robot}: {before} -> {after} triangles, {size / 1e6:.2f} MB, "
            f"worst 99th percentile {worst:.2f} mm"
        )
        total_before += before
        total_after += after
    print(f"all: {total_before} -> {total_after} triangles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
