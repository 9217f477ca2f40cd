"""How much memory a groom needs to render, and a refusal before the library allocates it."""

import os

RENDER_BYTES_PER_POINT = 220
"""What the library holds per hair point at its peak while it builds and renders a scene (its
copies of the points, the curve segments and Embree's BVH over them), with a margin."""
RENDER_BYTES_PER_CURVE = 64
"""The same per curve (its duplicated end points and its offsets)."""


def render_bytes_estimate(points, curves):
    """The bytes the library needs to build and render ``curves`` hair curves of ``points``
    points in all (what it holds beyond the exported arrays)."""
    return int(points) * RENDER_BYTES_PER_POINT + int(curves) * RENDER_BYTES_PER_CURVE


def available_memory_bytes():
    """The memory the system can still give this process (Linux' MemAvailable, else the free
    physical pages), or None where neither is known."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, OSError, ValueError):
        return None


def memory_problem(data, available):
    """None, or why the hair of ``data`` (SceneData) is refused: its estimated render memory
    exceeds ``available`` bytes (None: unknown, never refused). The refusal comes before the
    library allocates, so that a groom too big fails with a message instead of the system
    running out of memory."""
    if available is None or not data.curves:
        return None
    points = sum(curves.point_count for curves in data.curves)
    strands = sum(curves.curve_count for curves in data.curves)
    need = render_bytes_estimate(points, strands)
    if need <= available:
        return None
    return ("the hair of %d object(s) (%d strands, %d points) needs an estimated %.1f GB to "
            "render, more than the %.1f GB of memory available: render fewer strands (fewer "
            "children or curves, or fewer points per strand)"
            % (len(data.curves), strands, points, need / 1e9, available / 1e9))
