"""Blender values as numpy: matrices, points, a transform's radius scale, colours."""

import numpy as np


def matrix_of(matrix):
    """A mathutils 4×4 matrix as a float64 numpy array (row-major)."""
    return np.array([tuple(row) for row in matrix], dtype=np.float64)


def transform_points(matrix, points):
    """Applies a 4×4 numpy matrix to (n, 3) points."""
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def uniform_scale(matrix):
    """Cycles' radius scale for a transform: cbrt(|det(M3×3)|)."""
    return float(abs(np.linalg.det(matrix[:3, :3])) ** (1.0 / 3.0))


def warn_non_uniform_scale(obj, matrix, warn):
    """Cycles intersects the hair of a non-uniformly scaled object in object space (its tubes
    squashed by the scale); hairis renders round tubes in world space: a warning says so."""
    stretch = np.linalg.svd(matrix[:3, :3], compute_uv=False)
    if stretch[0] > 0.0 and stretch[-1] < stretch[0] * (1.0 - 1e-4):
        warn("object %r has a non-uniform scale (%s): Cycles renders its hair with strands "
             "squashed by that scale, hairis with round strands of the mean radius; apply the "
             "scale (Object > Apply > Scale) for the same image"
             % (obj.name, ", ".join("%.3g" % v for v in stretch)))


def rgb(value):
    return tuple(float(v) for v in tuple(value)[:3])
