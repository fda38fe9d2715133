"""pointrast: render point clouds by software rasterization in compute shaders, from Python.

    >>> import numpy as np, pointrast
    >>> xyz = np.random.default_rng(1).random((100_000, 3))
    >>> image = pointrast.render(xyz, width=640, height=480)     # (480, 640, 4) uint8, RGBA
    >>> cloud = pointrast.open("autzen.las")                      # LAS, LAZ, PLY, XYZ: every point
    >>> image = pointrast.render(cloud, color="classification", edl=True)
    >>> octree = pointrast.open("octree/")                         # Potree, COPC, EPT: level of detail
    >>> image = pointrast.render(octree, min_node_px=50)
    >>> pointrast.show(octree)                                      # Jupyter: the interactive viewer

The camera follows the CLI's contract: right-handed, z up, eye and target in the data's own coordinates,
the vertical field of view in degrees; without a camera, the CLI's overview (face on, 35° above the horizon).
Coordinates far from the origin (UTM, ECEF) are made relative to the cloud's center in double precision
before anything becomes float. Errors raise ValueError (bad input, with the CLI's sentence), TypeError (an
array of the wrong dtype) or RuntimeError (a device that cannot run what was asked).
"""

import io as _io
import math as _math
import os as _os

import numpy as _np

from . import _core

__all__ = ["Camera", "Cloud", "Frame", "Octree", "Renderer", "Viewer", "open", "render", "methods", "show"]

Cloud = _core.Cloud
Octree = _core.Octree


class Camera:
    """A camera: eye and target in the data's coordinates, up direction, vertical field of view in degrees.

    Camera(eye, target, up=(0, 0, 1), fov=60). A dict with the same keys works wherever a Camera does;
    in a dict, eye alone looks at the center of the bounds and fov alone keeps the overview's direction.
    `near` drops points at a linear depth at or below it (0: automatic).
    """

    def __init__(self, eye, target, up=(0.0, 0.0, 1.0), fov=60.0, near=0.0):
        self.eye = tuple(float(v) for v in eye)
        self.target = tuple(float(v) for v in target)
        self.up = tuple(float(v) for v in up)
        self.fov = float(fov)
        self.near = float(near)

    def to_dict(self):
        return {"eye": self.eye, "target": self.target, "up": self.up, "fov": self.fov, "near": self.near}

    @classmethod
    def from_dict(cls, d):
        return cls(d["eye"], d["target"], d.get("up", (0, 0, 1)), d.get("fov", 60.0), d.get("near", 0.0))

    def __repr__(self):
        return "Camera(eye=%r, target=%r, up=%r, fov=%r)" % (self.eye, self.target, self.up, self.fov)


class Frame:
    """A rendered frame: image (H, W, 4) uint8 RGBA, row 0 at the top; depth (H, W) float32 linear depth of
    the closest point (inf where none) and index (H, W) int64 index of that point (-1 where none) when
    asked for; the camera it was drawn from; gpu_ms, the GPU time of a frame (the median of `frames`);
    upload_s, the seconds this render spent uploading the cloud (0 when a Renderer reused it), of which
    upload_encode_s encoding it on the host and upload_copy_wait_s waiting for copies the encoding did not
    hide; upload_steps_cpu_s, the encoding's steps in seconds of all its threads together (read, bounds,
    words, colors, stage), the threads it had, allocate_wall, the seconds spent allocating buffers (~0
    where a Renderer reused the GPU memory of the cloud it drew before), and reused_bytes and
    allocated_bytes, the buffers' bytes reused and allocated.
    Shows itself as a PNG in Jupyter."""

    def __init__(self, result):
        self.image = result["image"]
        self.depth = result.get("depth")
        self.index = result.get("index")
        self.camera = Camera.from_dict(result["camera"])
        self.method = result["method"]
        self.points = result["points"]
        self.gpu_ms = result["gpu_ms"]
        self.upload_s = result.get("upload_s", 0.0)
        self.upload_encode_s = result.get("upload_encode_s", 0.0)
        self.upload_copy_wait_s = result.get("upload_copy_wait_s", 0.0)
        self.upload_steps_cpu_s = dict(result.get("upload_steps_cpu_s", {}))

    def _repr_png_(self):
        return png_bytes(self.image)

    def __repr__(self):
        h, w = self.image.shape[:2]
        return "<pointrast.Frame %dx%d, %s, %d points>" % (w, h, self.method, self.points)


def png_bytes(image):
    """The PNG file of an (H, W, 4) or (H, W, 3) uint8 image, as bytes (no dependency but zlib)."""
    import struct
    import zlib

    image = _np.ascontiguousarray(image, dtype=_np.uint8)
    h, w, c = image.shape
    rows = _np.concatenate([_np.zeros((h, 1), _np.uint8), image.reshape(h, w * c)], axis=1)

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", w, h, 8, 6 if c == 4 else 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)) +
            chunk(b"IEND", b""))


def methods():
    """The point methods' names (method=...), from the method table."""
    return list(_core.method_names())


def open(path, *, lod="auto"):
    """Open a point cloud file or an octree, as the CLI reads them.

    LAS, LAZ, PLY and XYZ files are read whole into a Cloud; Potree 2.0 folders, COPC and EPT open as an
    Octree, drawn with level of detail (its nodes are streamed from disk as a view needs them). lod=False
    reads every point of a COPC file into a Cloud instead; lod=True refuses what is not an octree.

    A Cloud looks like laspy's LasData: .x .y .z (float64), .X .Y .Z (int32, views without a copy),
    .red .green .blue (uint8 views), .intensity, .classification, .return_number, .point_source_id (None
    where the file has none), .header.scales and .header.offsets, len(cloud), .xyz (N, 3) float64.
    """
    path = _os.fspath(path)
    if not _os.path.exists(path):
        raise FileNotFoundError("%s: no such file or folder" % path)
    info = _core.probe(path)
    if info["particles"]:
        raise ValueError("%s holds particles (%s), which this module does not draw" % (path, info["format"]))
    if lod is True or (lod == "auto" and info["octree"]):
        return _core.open_octree(path)
    return _core.read_cloud(path)


def _cloud_property(name, doc, getter):
    setattr(Cloud, name, property(getter, doc=doc))


class _Header:
    def __init__(self, cloud):
        self.scales = _np.array(cloud.scales)
        self.offsets = _np.array(cloud.offsets)
        self.point_count = len(cloud)
        self.mins = _np.array(cloud.bounds[0])
        self.maxs = _np.array(cloud.bounds[1])


for _i, _axis in enumerate("xyz"):
    _cloud_property(_axis, "world %s (float64, a new array)" % _axis, lambda c, a=_i: c.world(a))
    _cloud_property(_axis.upper(), "quantized %s (int32 view)" % _axis, lambda c, a=_i: c.quantized(a))
for _i, _name in enumerate(("red", "green", "blue")):
    _cloud_property(_name, "%s channel (uint8 view; empty without colors)" % _name, lambda c, a=_i: c.color(a))
for _name in ("intensity", "classification", "return_number", "point_source_id"):
    _cloud_property(_name, "%s (a view; None where the data has none)" % _name, lambda c, n=_name: c.attribute(n))
_cloud_property("header", "scales, offsets, point_count, mins, maxs (as laspy's header)", lambda c: _Header(c))
_cloud_property("xyz", "(N, 3) float64 world coordinates", lambda c: _np.stack([c.world(0), c.world(1), c.world(2)], 1))
Cloud.__repr__ = lambda c: "<pointrast.Cloud %s, %d points>" % (c.source, len(c))


def _field(obj, name):
    value = getattr(obj, name, None)
    if value is None:
        return None
    return _np.asarray(value)


def _as_cloud(data, colors=None, intensity=None, classification=None):
    """A Cloud from what render() accepts: a Cloud, an (N, 3) array, or an object with .x .y .z."""
    if isinstance(data, (Cloud, Octree)):
        if colors is not None or intensity is not None or classification is not None:
            raise ValueError("colors, intensity and classification go with an array, not a %s"
                             % type(data).__name__)
        return data
    if isinstance(data, _np.ndarray):
        cloud = _core.cloud_from_xyz(data)
    elif all(hasattr(data, a) for a in ("x", "y", "z")):
        header = getattr(data, "header", None)
        X, Y, Z = (_field(data, a) for a in ("X", "Y", "Z"))
        if X is not None and header is not None and hasattr(header, "scales") and X.dtype == _np.int32:
            # laspy's LasData: the stored integers with their scale and offset, exactly as the file has them
            cloud = _core.cloud_from_quantized(X, Y, Z, [float(v) for v in header.scales],
                                               [float(v) for v in header.offsets])
        else:
            x, y, z = (_np.asarray(getattr(data, a), dtype=_np.float64) for a in ("x", "y", "z"))
            cloud = _core.cloud_from_xyz(_np.stack([x, y, z], axis=1))
        if colors is None and all(hasattr(data, a) for a in ("red", "green", "blue")):
            red = _field(data, "red")
            if red is not None and red.size:
                _core.set_colors(cloud, red, _field(data, "green"), _field(data, "blue"))
        for name in ("intensity", "classification", "return_number", "point_source_id"):
            values = _field(data, name)
            if values is not None and values.size and {"intensity": intensity,
                                                       "classification": classification}.get(name) is None:
                _core.set_attribute(cloud, name, values.astype(_attribute_dtype(name, values), copy=False))
    else:
        raise TypeError("render() takes an (N, 3) numpy array, a pointrast Cloud or Octree, or an object with "
                        ".x .y .z (laspy's LasData), not %s" % type(data).__name__)
    if colors is not None:
        colors = _np.asarray(colors) if not isinstance(colors, _np.ndarray) else colors
        if colors.ndim == 2 and colors.shape[1] == 3:
            _core.set_colors(cloud, colors[:, 0], colors[:, 1], colors[:, 2])
        elif colors.ndim == 1:
            _core.set_attribute(cloud, "intensity", colors)
        else:
            raise ValueError("colors must be (N, 3) red, green, blue or (N,) scalar values, not %r"
                             % (colors.shape,))
    if intensity is not None:
        _core.set_attribute(cloud, "intensity", _np.asarray(intensity))
    if classification is not None:
        _core.set_attribute(cloud, "classification", _np.asarray(classification))
    return cloud


def _attribute_dtype(name, values):
    if name == "intensity":
        return values.dtype if values.dtype in (_np.uint8, _np.uint16) else _np.uint16
    return _np.uint16 if name == "point_source_id" else _np.uint8


_DEFAULTS = dict(width=1920, height=1080, method="auto", depth="float", precision="adaptive",
                 background=(0, 0, 0), color="auto", color_range=None, point_size=1.0, point_shape="square",
                 point_size_mode="fixed", point_size_max=16.0, dilate=0, edl=False, edl_strength=None,
                 edl_radius=None, min_node_px=None, point_budget=None, gpu_memory=None, foveated=False,
                 fovea_radius=None, fovea_periphery=None, frames=1, clip_box=None, clip_polygon=None,
                 clip_z=None, clip_mode=None, classes=None, returns=None, intensity_range=None, gps_time=None,
                 source_ids=None)


def _options(kwargs, base):
    unknown = set(kwargs) - set(_DEFAULTS)
    if unknown:
        raise TypeError("unknown render option(s): %s; the options are %s"
                        % (", ".join(sorted(unknown)), ", ".join(_DEFAULTS)))
    options = dict(base)
    options.update(kwargs)
    if isinstance(options["gpu_memory"], str):
        options["gpu_memory"] = _bytes(options["gpu_memory"])
    if isinstance(options["point_budget"], str):
        options["point_budget"] = _count(options["point_budget"])
    return options


def _bytes(text):
    units = {"": 1, "k": 1 << 10, "m": 1 << 20, "g": 1 << 30, "t": 1 << 40}
    t = text.strip().lower().removesuffix("ib").removesuffix("b")
    unit = t[-1] if t and t[-1] in units else ""
    try:
        return int(float(t[:-1] if unit else t) * units[unit])
    except ValueError:
        raise ValueError("gpu_memory must be bytes, e.g. 8G or 512M, not %r" % text) from None


def _count(text):
    units = {"": 1, "k": 10**3, "m": 10**6, "g": 10**9}
    t = text.strip().lower()
    unit = t[-1] if t and t[-1] in units else ""
    try:
        return int(float(t[:-1] if unit else t) * units[unit])
    except ValueError:
        raise ValueError("point_budget must be a count, e.g. 100M, not %r" % text) from None


def _camera(camera):
    if camera is None or isinstance(camera, dict):
        return camera
    if isinstance(camera, Camera):
        return camera.to_dict()
    raise TypeError("camera must be a pointrast.Camera or a dict with eye, target, up, fov, not %s"
                    % type(camera).__name__)


class Renderer:
    """Keeps a Vulkan device, the uploaded cloud (or an octree's node cache) and a camera between renders.

        r = pointrast.Renderer(cloud, width=1280, height=720)
        r.orbit(30)                 # turn 30 degrees around the target
        frame = r.render(edl=True)  # a Frame: image, camera, ...
        hit = r.pick(640, 360)      # the point under a pixel: index, position, depth

    Keyword options given here are the defaults of every render(); render() takes the same ones again.
    device: the Vulkan device index (as `pointrast info --devices` lists them). Arrays are referenced, not
    copied (a batch method uploads them straight from where they lie): do not change them while the
    Renderer draws them; give it new arrays with set_scene() instead. A Renderer reuses its GPU memory for
    a new cloud of the same size or smaller (down to half the size): the upload of each frame of an
    animation or a parameter sweep allocates nothing (Frame.upload_steps_cpu_s["allocate_wall"] ~ 0).
    """

    def __init__(self, data, colors=None, *, camera=None, device=None, **options):
        self._scene = _as_cloud(data, colors)
        self._options = _options(options, _DEFAULTS)
        self._session = _core.Session(device)
        self.camera = None
        if camera is not None:
            self.camera = camera if isinstance(camera, Camera) else Camera.from_dict(_camera(camera))
        else:
            self.overview()

    @property
    def device(self):
        """The name of the Vulkan device."""
        return self._session.device_name

    @property
    def scene(self):
        """The Cloud or Octree drawn."""
        return self._scene

    def set_scene(self, data, colors=None):
        """Draw other points from now on: a Cloud, arrays as for the constructor, or an Octree; the camera
        stays. The next render uploads them into the GPU memory of the cloud drawn before where they fit (the
        same size or smaller, down to half), instead of allocating more."""
        self._scene = _as_cloud(data, colors)

    def _bounds(self):
        return self._scene.bounds

    def overview(self, fov=None):
        """Set the camera to the overview of the scene (the CLI's default camera) and return it."""
        fov = fov if fov is not None else (self.camera.fov if self.camera else 60.0)
        aspect = self._options["width"] / self._options["height"]
        self.camera = Camera.from_dict(_core.scene_overview_camera(self._scene, aspect, fov))
        return self.camera

    def look_at(self, eye, target, up=(0.0, 0.0, 1.0), fov=None):
        """Set the camera to look from eye at target and return it."""
        self.camera = Camera(eye, target, up, fov if fov is not None else self.camera.fov)
        return self.camera

    def orbit(self, yaw=0.0, pitch=0.0):
        """Turn the eye around the target: yaw degrees about the up axis (counter-clockwise seen from
        above), then pitch degrees towards the up axis (never over the pole). Returns the camera."""
        c = self.camera
        eye, target, up = (_np.array(v, dtype=_np.float64) for v in (c.eye, c.target, c.up))
        up = up / _np.linalg.norm(up)
        offset = eye - target
        offset = _rotate(offset, up, _math.radians(yaw))
        right = _np.cross(up, offset)
        if _np.linalg.norm(right) > 0 and pitch:
            right /= _np.linalg.norm(right)
            distance = _np.linalg.norm(offset)
            elevation = _math.asin(max(-1.0, min(1.0, _np.dot(offset, up) / distance)))
            limit = _math.radians(89.0)
            target_elevation = max(-limit, min(limit, elevation + _math.radians(pitch)))
            offset = _rotate(offset, right, -(target_elevation - elevation))
        self.camera = Camera(tuple(target + offset), c.target, c.up, c.fov, c.near)
        return self.camera

    def render(self, *, camera=None, return_depth=False, return_index=False, **options):
        """Render with the renderer's camera (or `camera`, which then becomes it) and return a Frame."""
        if camera is not None:
            self.camera = camera if isinstance(camera, Camera) else Camera.from_dict(_camera(camera))
        opts = _options(options, self._options)
        result = self._session.render(self._scene, self.camera.to_dict(), opts, return_depth, return_index)
        return Frame(result)

    def pick(self, x, y, **options):
        """The point drawn at pixel (x, y) (column, row from the top-left) with the current camera:
        a dict with index, position (x, y, z in the data's coordinates) and depth, or None where the pixel
        shows no point. Clouds only."""
        if isinstance(self._scene, Octree):
            raise ValueError("pick() works on clouds; an octree's points are not indexed")
        frame = self.render(return_depth=True, return_index=True, **options)
        h, w = frame.index.shape
        if not (0 <= x < w and 0 <= y < h):
            raise ValueError("pixel (%d, %d) lies outside the %dx%d image" % (x, y, w, h))
        index = int(frame.index[int(y), int(x)])
        if index < 0:
            return None
        return {"index": index, "position": self._scene.point(index), "depth": float(frame.depth[int(y), int(x)])}


def _rotate(v, axis, angle):
    """v rotated by angle (radians) about the unit axis (Rodrigues)."""
    c, s = _math.cos(angle), _math.sin(angle)
    return v * c + _np.cross(axis, v) * s + axis * _np.dot(axis, v) * (1 - c)


def render(xyz, colors=None, *, camera=None, return_depth=False, return_index=False, device=None,
           intensity=None, classification=None, **options):
    """Render points or an octree to an image: a numpy (H, W, 4) uint8 RGBA array, row 0 at the top.

    xyz: an (N, 3) float32 or float64 C-contiguous array; a Cloud or Octree from pointrast.open(); or an
    object with .x .y .z (laspy's LasData, whose .X .Y .Z and header scales and offsets are used exactly,
    with .red .green .blue and the other attributes it has).
    colors: (N, 3) uint8 or uint16 red, green, blue (16-bit values are shifted to 8 bits), or (N,) uint8 or
    uint16 scalar values drawn as intensity (color="intensity" by default then; color="elevation" also
    works). intensity, classification: per-point attributes for color="intensity" or "classification".
    camera: a Camera, a dict with eye, target, up, fov (near), or None for the overview.
    return_depth, return_index: return a Frame whose .depth (float32 linear depth, inf where empty) and
    .index (int64 point index, -1 where empty) are those of the closest point at each pixel (clouds of up
    to 16,777,215 points) instead of the image alone.

    Options, as the CLI's (render --help): width=1920, height=1080, method="auto" (atomicmin for a cloud,
    lod for an octree; pointrast.methods() lists them), depth="float"|"int40", precision="adaptive"|1|2|3,
    background=(r, g, b), color="auto"|"rgb"|"intensity"|"classification"|"elevation"|"return"|"source",
    color_range=(lo, hi), point_size, point_shape="square"|"disc", point_size_mode="fixed"|"attenuated",
    point_size_max, dilate, edl, edl_strength, edl_radius, frames (timed frames after a warm-up: the Frame's
    gpu_ms is their median); octrees: min_node_px (100), point_budget,
    gpu_memory ("8G" or bytes), foveated, fovea_radius, fovea_periphery. device: Vulkan device index.
    Filters, as the CLI's Filters options: clip_box=(xmin, ymin, zmin, xmax, ymax, zmax) or a list of boxes,
    clip_polygon=[(x, y), ...] or a list of polygons (extruded in z; clip_z=(zmin, zmax) bounds them),
    clip_mode="inside"|"outside"|"highlight" (clip volumes are drawn by the GPU, which skips whole batches
    and nodes outside); clouds only: classes=[2, 6], returns="all"|"first"|"last"|"only",
    intensity_range=(lo, hi) (the CLI's --intensity), gps_time=(lo, hi), source_ids=[1, 4].
    """
    scene = _as_cloud(xyz, colors, intensity, classification)
    if (colors is not None and _np.asarray(colors).ndim == 1 and options.get("color", "auto") == "auto"):
        options["color"] = "intensity"
    opts = _options(options, _DEFAULTS)
    session = _core.Session(device)
    result = session.render(scene, _camera(camera), opts, return_depth, return_index)
    if return_depth or return_index:
        return Frame(result)
    return result["image"]


def save_png(path, image):
    """Write an (H, W, 4) uint8 image (render()'s result) to a PNG file."""
    with _io.open(_os.fspath(path), "wb") as f:
        f.write(png_bytes(image))


from ._show import Viewer, cli_path, show  # noqa: E402  (show() uses the helpers above)
