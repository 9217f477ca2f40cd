"""Hair strands: particle hair and Curves objects → world-space points, radii and normals,
as Cycles 3.4 builds them (``intern/cycles/blender/curves.cpp``)."""

import numpy as np

from . import compat
from .convert import matrix_of, transform_points, uniform_scale, warn_non_uniform_scale
from .scene_data import CurvesData


def curve_normals(obj, curves, point_count, offsets, data):
    """The Curves' point normals as Cycles reads them, (kept points, 3) float32, or None.

    ``Curves.normals`` is Blender's ``curves_normals_point_domain_calc`` (the curves' normal
    mode), the array Cycles' ``export_hair_curves`` stores as the normal attribute. It is read
    by iterating the collection: its ``foreach_get`` copies from an array Blender has already
    freed (4.5 and 5.0: the first two normals come back as garbage), while an iteration keeps
    the array alive until it ends. Cycles uses the normals in object space, without the
    object's rotation, and so does hairis (a warning says so when the object is rotated).
    """
    source = getattr(curves, "normals", None)
    if source is None or len(source) != point_count:
        data.warn("object %r: its curve normals cannot be read in Blender %s; elliptical Huang "
                  "fibers on it use Cycles' fallback frame" % (obj.name, compat.version_string()))
        return None
    normals = np.fromiter((c for item in source for c in item.vector), np.float32,
                          count=3 * point_count).reshape(-1, 3)
    if not np.all(np.isfinite(normals)):
        data.warn("object %r: Blender gives non-finite curve normals; hairis uses zero (Cycles' "
                  "fallback frame) there" % obj.name)
        normals = np.where(np.isfinite(normals), normals, 0.0).astype(np.float32)
    keep = np.repeat(np.diff(np.asarray(offsets, np.int64)) >= 2, np.diff(offsets))
    matrix = matrix_of(obj.matrix_world)
    scale = uniform_scale(matrix)
    if scale > 0.0 and not np.allclose(matrix[:3, :3] / scale, np.eye(3), atol=1e-6):
        data.warn("object %r is rotated: Cycles orients elliptical Huang fibers by its curve "
                  "normals in object space (it does not rotate them with the object), and so "
                  "does hairis" % obj.name)
    return np.ascontiguousarray(normals[keep], np.float32)


def drop_short_curves(offsets, positions, radii):
    """Removes curves with fewer than 2 points; returns (first uint32, positions, radii, n)."""
    keep = np.diff(np.asarray(offsets, dtype=np.int64)) >= 2
    first, (positions, radii) = select_strands(offsets, keep, positions, radii)
    return first, positions, radii, int(np.count_nonzero(~keep))


def renderable_strands(first, positions, radii, numbers, label, warn):
    """The strands (curves) hairis renders, as a boolean mask, with a warning naming ``label``
    and counting the others, which are skipped.

    ``positions`` and ``radii`` are world space; they are judged as the float32 values the
    library gets. A strand with a NaN or infinite position or radius, or a negative radius, is
    skipped: Cycles (Embree) drops only the segments around such a point, which no valid
    strand can reproduce, and a refusal would cost the whole image; the warning names the
    strands (``numbers``: their indices as the artist counts them). Strands of zero length or
    zero radius are never hit, in Cycles either.
    """
    first = np.asarray(first, np.int64)
    counts = np.diff(first)
    positions = np.asarray(positions, np.float32)
    radii = np.asarray(radii, np.float32).reshape(-1)
    curve_of_point = np.repeat(np.arange(counts.size), counts)
    with np.errstate(invalid="ignore", over="ignore"):
        bad_point = ~np.isfinite(positions).all(axis=1) | ~(radii >= 0.0)
        invalid = np.zeros(counts.size, bool)
        invalid[curve_of_point[bad_point]] = True
        step = np.zeros(radii.size, np.float32)
        step[1:] = np.sqrt(np.sum(np.square(positions[1:] - positions[:-1]), axis=1))
        step[first[:-1]] = 0.0  # the step into a curve's first point is from another curve
        moves = np.maximum.reduceat(step, first[:-1]) > 0.0 if counts.size else invalid
        thick = np.maximum.reduceat(radii, first[:-1]) > 0.0 if counts.size else invalid
    zero_length = ~invalid & ~moves
    zero_radius = ~invalid & moves & ~thick
    if invalid.any():
        count = int(np.count_nonzero(invalid))
        listed = ", ".join(str(int(n)) for n in np.asarray(numbers)[invalid][:8])
        warn("%s: skipped %d strand(s) with a NaN or infinite position or a negative or NaN "
             "radius (strand%s %s%s); Cycles leaves out only the segments around such a point"
             % (label, count, "s" if count > 1 else "", listed, ", ..." if count > 8 else ""))
    if zero_length.any():
        warn("%s: skipped %d strand(s) of zero length (all points equal; Cycles shows nothing "
             "there either)" % (label, np.count_nonzero(zero_length)))
    if zero_radius.any():
        warn("%s: skipped %d strand(s) of zero radius (Cycles shows nothing there either)"
             % (label, np.count_nonzero(zero_radius)))
    return ~(invalid | zero_length | zero_radius)


def select_strands(first, keep, *arrays):
    """(first, arrays) of the strands ``keep`` selects: ``arrays`` hold one row per point
    (None passes through)."""
    first = np.asarray(first, np.int64)
    if keep.all():
        return first.astype(np.uint32), arrays
    counts = np.diff(first)
    point_keep = np.repeat(keep, counts)
    selected = tuple(None if a is None else a[point_keep] for a in arrays)
    kept_first = np.zeros(np.count_nonzero(keep) + 1, np.uint32)
    np.cumsum(counts[keep], out=kept_first[1:])
    return kept_first, selected


def shape_radius(time, shape, root, tip):
    """Cycles' ``shaperadius``: the strand radius at arc-length fraction ``time`` ∈ [0, 1]."""
    radius = 1.0 - np.asarray(time, dtype=np.float64)
    if shape < 0.0:
        radius = np.power(radius, 1.0 + shape)
    elif shape > 0.0:
        exponent = 1.0 / (1.0 - shape) if shape < 1.0 else np.inf
        with np.errstate(over="ignore"):
            radius = np.power(radius, exponent)
    return radius * (root - tip) + tip


def _particle_modifier(obj, psys):
    for modifier in obj.modifiers:
        if modifier.type == "PARTICLE_SYSTEM" and modifier.particle_system is not None \
                and modifier.particle_system.name == psys.name:
            return modifier
    return None


def particle_hair_points(obj, psys, first_particle, curve_count, key_count):
    """World positions (curve_count, key_count, 3) of strands from the path cache.

    Blender 3.4's Python API has no bulk accessor for the evaluated path cache:
    ``ParticleHairKey`` holds only the parents' edit keys (``co_local`` in each strand's
    hair space, and ``foreach_get("co")`` on evaluated keys crashes 3.4), and the Curves
    conversion is an operator that edits ``bpy.data``. So this is the one per-point call:
    ``co_hair`` streamed by a generator straight into ``np.fromiter`` (no Python list or
    Vector per point is kept). Everything after it is numpy.
    """
    co_hair = psys.co_hair
    stream = (c for particle in range(first_particle, first_particle + curve_count)
              for step in range(key_count)
              for c in co_hair(obj, particle_no=particle, step=step))
    count = curve_count * key_count * 3
    points = np.fromiter(stream, dtype=np.float32, count=count)
    return points.reshape(curve_count, key_count, 3).astype(np.float64)


def export_particle_hair(exporter, obj):
    """Exports every rendered hair particle system of the evaluated object ``obj``."""
    data = exporter.data
    matrix = matrix_of(obj.matrix_world)
    try:
        inverse = np.linalg.inv(matrix)
    except np.linalg.LinAlgError:
        data.warn("object %r has a singular matrix; its particle hair is skipped" % obj.name)
        return
    scale = uniform_scale(matrix)
    if any(p.settings.type == "HAIR" for p in obj.particle_systems):
        warn_non_uniform_scale(obj, matrix, data.warn)
    exported = 0  # strands of this object so far: Cycles numbers them across its systems
    for psys in obj.particle_systems:
        settings = psys.settings
        if settings.type != "HAIR" or settings.render_type != "PATH":
            continue
        modifier = _particle_modifier(obj, psys)
        if modifier is not None:
            enabled = modifier.show_render if exporter.background else modifier.show_viewport
            if not enabled:
                continue
        parent_count = len(psys.particles)
        child_count = len(psys.child_particles)
        if not exporter.background:
            child_count = int(child_count * settings.display_percentage / 100.0)
        if settings.child_type == "NONE" or child_count == 0:
            first_particle, curve_count = 0, parent_count + child_count
        else:
            first_particle, curve_count = parent_count, child_count
        if curve_count == 0:
            continue
        steps = settings.render_step if exporter.background else settings.display_step
        key_count = (1 << steps) + 1
        if settings.kink == "SPIRAL":
            key_count += settings.kink_extra_steps
        points = particle_hair_points(obj, psys, first_particle, curve_count, key_count)
        # co_hair gives (0, 0, 0) where the cache has no key: repeat the previous key, as
        # Cycles does, and drop strands with no key at all.
        valid = np.any(points != 0.0, axis=2)
        present = valid.any(axis=1)
        indices = exported + np.nonzero(present)[0]  # Cycles numbers the object's strands
        exported += int(present.size)
        if not present.all():
            points, valid = points[present], valid[present]
            curve_count = points.shape[0]
            if curve_count == 0:
                continue
        index = np.where(valid, np.arange(key_count)[None, :], 0)
        np.maximum.accumulate(index, axis=1, out=index)
        points = np.take_along_axis(points, index[:, :, None], axis=1)
        # Arc-length fraction in object space, as Cycles.
        local = transform_points(inverse, points.reshape(-1, 3)).reshape(points.shape)
        segment = np.linalg.norm(np.diff(local, axis=1), axis=2)
        length = np.concatenate([np.zeros((curve_count, 1)), np.cumsum(segment, axis=1)], axis=1)
        total = length[:, -1:]
        time = np.divide(length, total, out=np.zeros_like(length), where=total > 0.0)
        half = settings.radius_scale * 0.5
        radii = shape_radius(time, settings.shape, half * settings.root_radius,
                             half * settings.tip_radius)
        if settings.use_close_tip:
            radii[:, -1] = 0.0
        radii *= scale
        material = exporter.material(exporter.slot_material(obj, settings.material - 1),
                                     for_hair=True)
        first = np.arange(curve_count + 1, dtype=np.uint32) * np.uint32(key_count)
        points, local, radii = points.reshape(-1, 3), local.reshape(-1, 3), radii.reshape(-1)
        keep = renderable_strands(first, points, radii, indices - exported + present.size,
                                  "object %r, particle system %r" % (obj.name, psys.name),
                                  data.warn)
        first, (points, local, radii) = select_strands(first, keep, points, local, radii)
        indices = indices[keep]
        if first.size < 2:
            continue
        data.curves.append(CurvesData(
            name="%s/%s" % (obj.name, psys.name), source="PARTICLES", material=material,
            first=first, positions=points.astype(np.float32), radii=radii.astype(np.float32),
            inputs=exporter.strand_inputs(material, first, local, indices)))
