"""The demo's product shot, built by script: a bust with long, styled hair in a studio.

Everything is procedural. The bust is two meshes (head; neck and shoulders) whose surfaces are
signed distance functions, smooth unions of ellipsoids and capsules, meshed by moving each
vertex of a UV sphere along its ray to the surface, then smoothed by a Subdivision Surface
modifier. The hair is a Curves object whose points are written by script, so Blender 3.4, 4.5
and 5.0 build the same strands: roots on the scalp, combed away from a side part, bent down by
gravity and kept outside the bust, then gathered into clumps with waves and a little frizz.
A Principled Hair BSDF (Chiang, Melanin) shades it; a Principled BSDF the skin; a backdrop and
three area lights (key, fill, rim) make the studio.

Blender units are decimetres here: the head is about 2.3 units from chin to crown.
"""

import math

import bpy
import numpy as np
from mathutils import Vector

import helpers  # tests/blender: the scene helpers shared with the add-on's tests

UP = np.array([0.0, 0.0, 1.0])


# ---- Signed distances (numpy, points of shape (..., 3)) --------------------------------------

def ellipsoid(p, center, radii):
    """An approximate signed distance to an ellipsoid (exact on its surface)."""
    x, y, z = ((p[..., i] - center[i]) / radii[i] for i in range(3))
    k0 = np.sqrt(x * x + y * y + z * z)
    x, y, z = x / radii[0], y / radii[1], z / radii[2]
    k1 = np.sqrt(x * x + y * y + z * z)
    return k0 * (k0 - 1.0) / np.maximum(k1, 1e-9)


def capsule(p, a, b, radius_a, radius_b):
    """Signed distance to a capsule from ``a`` to ``b`` whose radius tapers linearly."""
    a, b = np.asarray(a), np.asarray(b)
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    x, y, z = (p[..., i] - a[i] - t * ab[i] for i in range(3))
    return np.sqrt(x * x + y * y + z * z) - (radius_a + (radius_b - radius_a) * t)


def smooth_union(a, b, k):
    """Polynomial smooth minimum: the union of two shapes with a fillet of size ``k``."""
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return b + (a - b) * h - k * h * (1.0 - h)


def smooth_subtract(a, b, k):
    """Shape ``a`` with shape ``b`` carved out, filleted by ``k``."""
    return -smooth_union(-a, b, k)


def head_distance(p):
    """The head: cranium, face, jaw, chin, brow, nose, lips and cheeks; eye sockets carved."""
    d = ellipsoid(p, (0.0, 0.12, 0.22), (0.76, 0.98, 0.9))
    d = smooth_union(d, ellipsoid(p, (0.0, -0.28, -0.34), (0.6, 0.62, 0.72)), 0.25)
    d = smooth_union(d, ellipsoid(p, (0.0, -0.55, -0.88), (0.32, 0.3, 0.3)), 0.25)
    d = smooth_union(d, ellipsoid(p, (0.0, -0.82, 0.08), (0.5, 0.2, 0.16)), 0.15)
    for side in (-1.0, 1.0):
        d = smooth_union(d, ellipsoid(p, (0.34 * side, -0.7, -0.38), (0.22, 0.2, 0.2)), 0.15)
        d = smooth_subtract(d, ellipsoid(p, (0.3 * side, -0.98, -0.06), (0.15, 0.1, 0.09)),
                            0.1)
        d = smooth_union(d, ellipsoid(p, (0.77 * side, 0.02, -0.2), (0.07, 0.2, 0.3)), 0.08)
    d = smooth_union(d, capsule(p, (0.0, -1.0, -0.05), (0.0, -1.12, -0.5), 0.07, 0.12), 0.08)
    d = smooth_union(d, ellipsoid(p, (0.0, -0.86, -0.72), (0.2, 0.1, 0.08)), 0.06)
    return d


def body_distance(p):
    """Neck, shoulders and chest, cut off well below the frame."""
    d = capsule(p, (0.0, 0.12, -0.5), (0.0, 0.25, -2.0), 0.5, 0.58)
    torso = ellipsoid(p, (0.0, 0.2, -3.8), (1.55, 0.95, 2.0))
    for side in (-1.0, 1.0):
        torso = smooth_union(torso, capsule(p, (0.4 * side, 0.3, -2.2),
                                            (1.55 * side, 0.3, -2.6), 0.42, 0.5), 0.7)
    return smooth_union(d, torso, 0.45)


def bust_distance(p):
    """Head and body together: what the hair rests on."""
    return smooth_union(head_distance(p), body_distance(p), 0.2)


def unit(v):
    """``v`` (..., 3) scaled to unit length."""
    return v / np.maximum(np.sqrt(np.sum(v * v, axis=-1, keepdims=True)), 1e-12)


def gradient(distance, p, value=None, step=1e-3):
    """The unit gradient of ``distance`` at ``p`` by forward differences (``value``: the
    distance at ``p`` when known)."""
    if value is None:
        value = distance(p)
    return unit(np.stack([distance(p + step * e) - value for e in np.eye(3)], axis=-1))


def surface_along_rays(distance, center, directions, reach, steps=48):
    """Where rays from ``center`` along unit ``directions`` last leave the shape (bisection
    after a march inwards from ``reach``): the star-shaped part of the surface."""
    center = np.asarray(center)
    ts = np.linspace(reach, 0.0, steps)
    inside = np.stack([distance(center + t * directions) < 0.0 for t in ts], axis=0)
    first = np.argmax(inside, axis=0)  # the first sample inside, marching in
    hi = ts[np.maximum(first - 1, 0)]
    lo = ts[first]
    for _ in range(20):
        mid = 0.5 * (lo + hi)
        out = distance(center + mid[:, None] * directions) > 0.0
        hi = np.where(out, mid, hi)
        lo = np.where(out, lo, mid)
    return center + (0.5 * (lo + hi))[:, None] * directions


# ---- The bust --------------------------------------------------------------------------------

def sphere_grid(segments, rings):
    """Unit directions and quad/triangle faces of a UV sphere (poles as single vertices)."""
    theta = np.linspace(0.0, math.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    ring_dirs = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], -1)
    directions = np.concatenate([[[0.0, 0.0, 1.0]], ring_dirs.reshape(-1, 3),
                                 [[0.0, 0.0, -1.0]]])
    bottom = len(directions) - 1

    def at(ring, segment):
        return 1 + ring * segments + segment % segments

    faces = [(0, at(0, s + 1), at(0, s)) for s in range(segments)]
    for r in range(rings - 2):
        faces += [(at(r, s), at(r, s + 1), at(r + 1, s + 1), at(r + 1, s))
                  for s in range(segments)]
    faces += [(at(rings - 2, s), at(rings - 2, s + 1), bottom) for s in range(segments)]
    return directions, faces


def make_star_mesh(scene, name, distance, center, reach, material, segments=96, rings=64):
    """A smooth mesh of the shape ``distance`` seen from ``center`` (subdivided once)."""
    directions, faces = sphere_grid(segments, rings)
    vertices = surface_along_rays(distance, center, directions, reach)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], faces)
    if hasattr(mesh, "shade_smooth"):  # Blender 4.1+; 3.4 keeps smoothness per polygon
        mesh.shade_smooth()
    else:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    mesh.materials.append(material)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    subdivision = obj.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels = subdivision.render_levels = 1
    return obj


# ---- The hair --------------------------------------------------------------------------------

HEAD_CENTER = np.array([0.0, 0.05, 0.05])
PART = (np.array([0.28, -0.75, 0.9]), np.array([0.12, 0.45, 1.15]))
"""The side part, from the front hairline to the crown (on the wearer's left)."""


def hairline_elevation(azimuth):
    """Lowest root elevation (radians, seen from the head's centre) at ``azimuth`` (0 at the
    front, ±π at the back): forehead, temples, above the ears, nape."""
    knots = np.radians([0.0, 40.0, 75.0, 105.0, 140.0, 180.0])
    levels = np.radians([38.0, 32.0, 26.0, 14.0, -25.0, -42.0])
    return np.interp(np.abs(azimuth), knots, levels)


def scalp_roots(count, rng):
    """``count`` root positions and normals, spread evenly over the scalp."""
    roots, normals = np.zeros((0, 3)), np.zeros((0, 3))
    while len(roots) < count:
        directions = unit(rng.normal(size=(3 * count, 3)))
        elevation = np.arcsin(directions[:, 2])
        azimuth = np.arctan2(directions[:, 0], -directions[:, 1])
        # A soft hairline: sparser strands in its last few degrees.
        margin = elevation - hairline_elevation(azimuth)
        directions = directions[margin > rng.uniform(0.0, math.radians(6.0), len(margin))]
        points = surface_along_rays(head_distance, HEAD_CENTER, directions, 2.0, steps=4)
        n = gradient(head_distance, points)
        # Uniform directions give a density per area of cos / r²: even it out.
        r = points - HEAD_CENTER
        weight = np.sum(r * r, axis=1) / np.maximum(np.sum(n * directions, axis=1), 0.2)
        keep = rng.uniform(0.0, 3.0, len(weight)) < weight
        roots = np.concatenate([roots, points[keep]])
        normals = np.concatenate([normals, n[keep]])
    return roots[:count], normals[:count]


def comb_directions(roots, normals):
    """Initial strand directions along the scalp: sideways away from the part and back from
    the face in front of the crown, away from the crown behind it; lifted off the scalp."""
    start, end = PART
    x_part = np.interp(roots[:, 1], [start[1], end[1]], [start[0], end[0]])
    side = np.where(roots[:, 0] > x_part, 1.0, -1.0)
    back = np.interp(roots[:, 1], [-0.9, -0.3, end[1]], [1.2, 0.5, 0.2])
    up = np.interp(roots[:, 1], [-0.9, -0.4, end[1]], [1.0, 0.2, -0.3])
    front = np.stack([side, back, up], axis=1)
    behind = unit(roots - end) + np.array([0.0, 0.0, -0.3])
    w = np.clip((roots[:, 1] - end[1] + 0.3) / 0.5, 0.0, 1.0)[:, None]
    away = (1.0 - w) * unit(front) + w * unit(behind)
    tangent = unit(away - np.sum(away * normals, axis=1, keepdims=True) * normals)
    return unit(tangent + 0.3 * normals)


def push_out(points, offset):
    """Moves ``points`` closer to the bust than their ``offset`` out to that distance."""
    depth = bust_distance(points) - offset
    inside = depth < 0.0
    if inside.any():
        p = points[inside]
        g = gradient(bust_distance, p, depth[inside] + offset[inside])
        points[inside] = p - depth[inside, None] * g
    return points


def grow_strands(roots, normals, lengths, segments, rng):
    """Strand points (count, segments + 1, 3): each step turns the strand towards the ground
    and pushes it outside the bust by its layer's thickness (higher roots lie on top)."""
    count = len(roots)
    direction = comb_directions(roots, normals)
    height = np.clip((roots[:, 2] + 0.6) / 1.8, 0.0, 1.0)
    layer = 0.03 + 0.18 * height ** 1.5 + rng.uniform(0.0, 0.04, count)
    # Strands from the front of the head fall over the shoulders to the front, the others
    # behind them.
    front = roots[:, 1] < rng.uniform(-0.35, 0.05, count)
    forwards = np.where(front, -1.0, 1.0)
    step = (lengths / segments)[:, None]
    points = np.empty((count, segments + 1, 3))
    points[:, 0] = roots
    p = roots + 0.02 * normals
    stiffness = rng.uniform(2.0, 3.0, count)[:, None]
    # Strands from the forehead are swept back further than the others before they fall.
    styled = 1.0 + 1.2 * np.clip((-roots[:, 1] - 0.2) / 0.6, 0.0, 1.0)[:, None]
    for k in range(1, segments + 1):
        # Styled near the root: the strand hugs the scalp, and gravity takes over along the
        # first decimetre.
        weight = np.minimum(1.0, 0.15 + k * step / styled)
        # Below the jaw: away from the neck, then forwards or backwards off the shoulders.
        below = p[:, 2] < -1.0
        outwards = np.sign(p[:, 0]) * 0.8 * np.clip((0.9 - np.abs(p[:, 0])) / 0.3, 0.0, 1.0)
        drift = np.stack([outwards, forwards, np.zeros(count)], axis=1)
        pull = weight * -UP + np.where(below[:, None], drift, 0.0)
        if (weight < 1.0).any():
            pull = pull - (1.0 - weight) * gradient(bust_distance, p)
        # Stiff near the root, limp towards the tip (no strand flies off a shoulder).
        direction = unit(stiffness * (1.0 - 0.6 * k / segments) * direction + pull)
        q = push_out(push_out(p + step * direction, layer), layer)
        direction = unit(q - p)
        p = p + step * direction
        points[:, k] = p
    return points


def clump_and_wave(points, clump_count, rng):
    """Gathers strands towards their clump's leader towards the tips, and adds each clump's
    waves and each strand's frizz (all growing from root to tip)."""
    count, n = points.shape[:2]
    leaders = rng.choice(count, clump_count, replace=False)
    # A strand joins the leader nearest at its root, middle and tip (strands from either side
    # of the part stay apart): argmin of |c|² − 2 s·c over the leaders c.
    shape = points[:, [0, n // 2, n - 1]].reshape(count, 9)
    centers = shape[leaders]
    member = np.argmin(np.sum(centers * centers, axis=1)[None, :] - 2.0 * shape @ centers.T,
                       axis=1)
    t = np.linspace(0.0, 1.0, n)[None, :, None]
    tightness = rng.uniform(0.45, 0.85, clump_count)[member][:, None, None]
    leader_points = points[leaders][member]
    clumped = points + tightness * np.minimum(1.0, 1.6 * t) ** 1.3 * (leader_points - points)
    # Waves: each clump sways sideways (perpendicular to the strand and to the view of the
    # scalp) with its own phase and amplitude.
    side = unit(np.cross(unit(np.gradient(clumped, axis=1)), UP))
    phase = rng.uniform(0.0, 2.0 * math.pi, clump_count)[member][:, None, None]
    amplitude = rng.uniform(0.06, 0.14, clump_count)[member][:, None, None]
    waves = amplitude * t ** 1.5 * np.sin(2.0 * math.pi * 1.6 * t + phase)
    frizz = rng.normal(0.0, 1.0, (count, n, 3)) * (0.0015 + 0.008 * t ** 3)
    frizz = (frizz + np.roll(frizz, 1, axis=1)) * 0.5
    frizz[:, 0] = 0.0
    return clumped + waves * side + frizz


def keep_outside(points, margin=0.01):
    """Moves points that clumping pushed into the bust back onto its surface (plus margin)."""
    flat = points.reshape(-1, 3)
    offset = np.full(len(flat), margin)
    return push_out(push_out(flat, offset), offset).reshape(points.shape)


def make_hair(scene, material, count, segments=24, seed=11):
    """The Curves object of ``count`` strands of ``segments`` segments."""
    rng = np.random.default_rng(seed)
    roots, normals = scalp_roots(count, rng)
    lengths = 5.2 * rng.uniform(0.88, 1.0, count)
    points = grow_strands(roots, normals, lengths, segments, rng)
    points = clump_and_wave(points, max(1, count // 40), rng)
    points[:, 1:] = keep_outside(points[:, 1:].copy())
    n = segments + 1
    obj = new_curves(scene, "Hair", count, n)
    curves = obj.data
    curves.position_data.foreach_set("vector", points.astype(np.float32).reshape(-1))
    t = np.linspace(0.0, 1.0, n)
    radius = np.tile(0.0032 * (1.0 - 0.7 * t ** 2), count).astype(np.float32)
    attribute = curves.attributes.get("radius") or curves.attributes.new("radius", "FLOAT",
                                                                         "POINT")
    attribute.data.foreach_set("value", radius)
    curves.materials.append(material)
    return obj


def new_curves(scene, name, count, points_per_curve):
    """A Curves object of ``count`` curves of ``points_per_curve`` points each, positions to be
    written. Blender 3.4's Python API cannot size a Curves datablock, so there the curves come
    from a legacy curve of poly splines converted to Curves."""
    if hasattr(bpy.types.Curves, "add_curves"):
        curves = bpy.data.hair_curves.new(name)
        curves.add_curves([points_per_curve] * count)
        obj = bpy.data.objects.new(name, curves)
        scene.collection.objects.link(obj)
        return obj
    legacy = bpy.data.curves.new(name, "CURVE")
    zeros = np.zeros(4 * points_per_curve, dtype=np.float32)
    for _ in range(count):
        spline = legacy.splines.new("POLY")
        spline.points.add(points_per_curve - 1)
        spline.points.foreach_set("co", zeros)
    obj = bpy.data.objects.new(name, legacy)
    scene.collection.objects.link(obj)
    for other in scene.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.object.convert(target="CURVES") == {"FINISHED"}
    obj = bpy.context.view_layer.objects.active
    assert obj.type == "CURVES" and len(obj.data.curves) == count, (obj.type, count)
    obj.name = obj.data.name = name
    return obj


# ---- Materials, studio, camera ---------------------------------------------------------------

def make_hair_material():
    """Brunette hair with a warm cast: Chiang's model (Melanin), some variation per strand,
    darker at the roots."""
    material = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.6, "Melanin Redness": 0.6, "Roughness": 0.24,
        "Radial Roughness": 0.35, "Coat": 0.0, "IOR": 1.55})
    hair = material.node_tree.nodes["Principled Hair BSDF"]
    if hasattr(hair, "model"):  # Blender 4.0+ has Huang too; the demo is Chiang everywhere
        hair.model = "CHIANG"
    helpers.vary_melanin(material, random_color=0.15, random_roughness=0.2)
    ramp = next(n for n in material.node_tree.nodes if n.type == "VALTORGB")
    ramp.color_ramp.elements[0].color = (0.7, 0.7, 0.7, 1.0)
    ramp.color_ramp.elements[1].color = (0.55, 0.55, 0.55, 1.0)
    ramp.color_ramp.elements[1].position = 0.35
    return material


def look_at(obj, target):
    """Points an object's -Z axis (a camera's or light's view) at ``target``."""
    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def area_light(scene, name, location, target, power, size):
    """A square area light at ``location`` aimed at ``target``."""
    light = helpers.make_light(scene, "AREA", name, location=location, energy=power,
                               shape="SQUARE", size=size)
    look_at(light, target)
    return light


def make_backdrop(scene, camera_location, target, distance=9.0, size=60.0):
    """A plain diffuse wall behind the bust, facing the camera."""
    material = helpers.make_diffuse_material("Backdrop", (0.16, 0.17, 0.19, 1.0))
    view = (Vector(target) - Vector(camera_location)).normalized()
    mesh = bpy.data.meshes.new("Backdrop")
    half = size / 2.0
    mesh.from_pydata([(-half, -half, 0.0), (half, -half, 0.0), (half, half, 0.0),
                      (-half, half, 0.0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new("Backdrop", mesh)
    obj.location = Vector(target) + distance * view
    look_at(obj, Vector(target) + 2.0 * distance * view)  # its normal (+Z) faces the camera
    scene.collection.objects.link(obj)
    return obj


def make_product_head(resolution=(640, 640), strands=60000, segments=24):
    """The demo scene (scripts/render_demo.py): a bust with long brunette hair in a studio,
    rendered by Hairis. Returns the scene."""
    scene = helpers.reset()
    scene.render.engine = "HAIRIS"
    target = (0.0, 0.0, -1.1)
    camera_location = (-4.5, -13.9, 1.0)
    camera = helpers.make_camera(scene, location=camera_location, resolution=resolution,
                                 percentage=100)
    camera.data.lens = 85.0
    look_at(camera, target)
    helpers.make_world(scene, color=(0.6, 0.7, 0.85), strength=0.04)
    skin, _ = helpers.make_principled_material("Skin", **{
        "Base Color": (0.7, 0.48, 0.38, 1.0), "Roughness": 0.45})
    make_star_mesh(scene, "Head", head_distance, HEAD_CENTER, 2.0, skin)
    make_star_mesh(scene, "Body", body_distance, (0.0, 0.2, -2.4), 4.5, skin)
    make_hair(scene, make_hair_material(), strands, segments)
    make_backdrop(scene, camera_location, target)
    area_light(scene, "Key", (4.0, -8.0, 5.0), (0.0, 0.0, -0.5), 1800.0, 4.0)
    area_light(scene, "Fill", (-9.0, -5.0, -1.0), target, 500.0, 6.0)
    area_light(scene, "Rim", (3.5, 7.0, 4.5), (0.0, 0.0, -0.3), 1600.0, 2.5)
    bpy.context.view_layer.update()
    return scene
