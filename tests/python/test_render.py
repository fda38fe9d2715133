# render() against the CLI: the same data and camera give the same image, bit for bit.
import numpy as np
import pytest

import pointrast

from conftest import rgb

W, H = 256, 192
EYE, TARGET = (636000.0, 848900.0, 700.0), (636600.0, 849200.0, 450.0)


def utm_points(tmp_path, n, seed):
    """n float64 points far from the origin (UTM) with uint8 colors, and the same numbers as an XYZ file
    the CLI reads."""
    rng = np.random.default_rng(seed)
    xyz = np.empty((n, 3))
    xyz[:, 0] = 500_000.0 + rng.random(n) * 300.0  # UTM easting
    xyz[:, 1] = 5_400_000.0 + rng.random(n) * 200.0
    xyz[:, 2] = 100.0 + rng.random(n) * 20.0
    colors = rng.integers(0, 256, (n, 3), dtype=np.uint8)
    path = tmp_path / "utm.xyz"
    with open(path, "w") as f:
        for p, c in zip(xyz, colors):
            f.write("%.17g %.17g %.17g %d %d %d\n" % (p[0], p[1], p[2], c[0], c[1], c[2]))
    return xyz, colors, path


def test_las_cloud_equals_cli(data, cli):
    las = data / "las" / "autzen_trim.las"
    cloud = pointrast.open(las)
    assert isinstance(cloud, pointrast.Cloud) and len(cloud) > 100_000
    image = pointrast.render(cloud, width=W, height=H)
    assert image.shape == (H, W, 4) and image.dtype == np.uint8
    assert np.array_equal(rgb(image), cli(las, "--width", W, "--height", H))
    assert (image[..., 3] == 255).all()


def test_camera_equals_cli(data, cli):
    las = data / "las" / "autzen_trim.las"
    cloud = pointrast.open(las)
    camera = pointrast.Camera(EYE, TARGET, fov=50)
    image = pointrast.render(cloud, camera=camera, width=W, height=H)
    expected = cli(las, "--width", W, "--height", H, "--eye", "636000,848900,700", "--target",
                   "636600,849200,450", "--fov", 50)
    assert np.array_equal(rgb(image), expected)
    # a dict is the same camera
    same = pointrast.render(cloud, camera={"eye": EYE, "target": TARGET, "fov": 50}, width=W, height=H)
    assert np.array_equal(same, image)
    # and another camera another image
    other = pointrast.render(cloud, camera={"eye": EYE, "target": TARGET, "fov": 30}, width=W, height=H)
    assert not np.array_equal(other, image)


def test_laspy_like_object_equals_cli(data, cli):
    """An object with .X .Y .Z, header scales and offsets and .red .green .blue (laspy's LasData)."""
    las = data / "las" / "autzen_trim.las"
    cloud = pointrast.open(las)

    class Header:
        scales = np.array(cloud.header.scales)
        offsets = np.array(cloud.header.offsets)

    class LasData:  # what laspy gives: strided views of its point records
        header = Header()
        X, Y, Z = cloud.X, cloud.Y, cloud.Z
        x, y, z = cloud.x, cloud.y, cloud.z
        red = cloud.red.astype(np.uint16) * 256  # laspy's 16-bit colors
        green = cloud.green.astype(np.uint16) * 256
        blue = cloud.blue.astype(np.uint16) * 256

    assert cloud.X.strides == (12,)  # a view of the cloud, not a copy
    image = pointrast.render(LasData(), width=W, height=H)
    assert np.array_equal(rgb(image), cli(las, "--width", W, "--height", H))


def test_options_equal_cli(data, cli):
    las = data / "las" / "autzen_trim.las"
    cloud = pointrast.open(las)
    image = pointrast.render(cloud, width=W, height=H, color="classification", point_size=3, edl=True,
                             dilate=1, method="reduce-earlyz")
    expected = cli(las, "--width", W, "--height", H, "--color", "classification", "--point-size", 3, "--edl",
                   "--dilate", 1, "--method", "reduce-earlyz")
    assert np.array_equal(rgb(image), expected)
    plain = pointrast.render(cloud, width=W, height=H, color="classification")
    assert not np.array_equal(plain, image)


def test_float64_utm_array_equals_cli(tmp_path, cli):
    """float64 coordinates far from the origin render like the same numbers read by the CLI."""
    xyz, colors, path = utm_points(tmp_path, 20_000, seed=7)
    image = pointrast.render(xyz, colors, width=W, height=H)
    assert np.array_equal(rgb(image), cli(path, "--width", W, "--height", H))
    assert (rgb(image).sum(axis=2) > 0).mean() > 0.1  # the points cover much of the image
    # float32 input is read as it is, also without a copy
    image32 = pointrast.render((xyz - xyz.min(axis=0)).astype(np.float32), colors, width=W, height=H)
    assert image32.shape == (H, W, 4)


def test_depth_and_index(data, cli):
    las = data / "las" / "autzen_trim.las"
    cloud = pointrast.open(las)
    camera = pointrast.Camera(EYE, TARGET)
    frame = pointrast.render(cloud, camera=camera, width=W, height=H, return_depth=True, return_index=True)
    assert frame.depth.dtype == np.float32 and frame.index.dtype == np.int64
    hit = frame.index >= 0
    assert hit.mean() > 0.2
    assert np.isinf(frame.depth[~hit]).all()
    # each pixel's index is a point that projects onto that pixel, at that pixel's depth, with its color
    eye, target = np.array(EYE), np.array(TARGET)
    forward = (target - eye) / np.linalg.norm(target - eye)
    ys, xs = np.nonzero(hit)
    idx = frame.index[ys, xs]
    points = np.stack([cloud.x[idx], cloud.y[idx], cloud.z[idx]], 1)
    linear = (points - eye) @ forward
    assert np.allclose(frame.depth[ys, xs], linear, rtol=1e-4)
    colors = np.stack([cloud.red[idx], cloud.green[idx], cloud.blue[idx]], 1)
    same_color = (frame.image[ys, xs, :3] == colors).all(axis=1)
    assert same_color.mean() > 0.99  # ties at equal depth may show another point's color
    # the CLI's image is the image of the frame
    expected = cli(las, "--width", W, "--height", H, "--eye", "636000,848900,700", "--target", "636600,849200,450")
    assert np.array_equal(rgb(frame.image), expected)


def test_png_repr(data, tmp_path):
    """A Frame shows itself as a PNG in Jupyter: the image, losslessly."""
    from pngread import read_png

    cloud = pointrast.open(data / "las" / "autzen_trim.las")
    frame = pointrast.render(cloud, width=64, height=48, return_depth=True)
    path = tmp_path / "frame.png"
    path.write_bytes(frame._repr_png_())
    assert np.array_equal(read_png(path), frame.image)


@pytest.mark.parametrize("method", ["batch-prefetch", "batch"])
def test_arrays_uploaded_straight_equal_cli(tmp_path, cli, method):
    """Arrays with RGB colors drawn by a batch method are encoded straight from the arrays, without a cloud
    on the host: the image equals the CLI's of the same numbers, and the cloud made from the same arrays."""
    n = 25_000  # three batches, the last one short
    xyz, colors, path = utm_points(tmp_path, n, seed=11)
    straight = pointrast.Renderer(xyz, colors, width=W, height=H, method=method)
    image = straight.render().image
    assert straight.scene._arrays_only  # no PointCloud was made on the host
    assert np.array_equal(rgb(image), cli(path, "--width", W, "--height", H, "--method", method))
    assert (rgb(image).sum(axis=2) > 0).mean() > 0.1
    # The same Cloud once its PointCloud exists (reading its positions makes it): the same image.
    cloud = pointrast._as_cloud(xyz, colors)
    assert cloud._arrays_only
    assert len(cloud.quantized(0)) == n
    assert not cloud._arrays_only
    made = pointrast.render(cloud, width=W, height=H, method=method)
    assert np.array_equal(made, image)
    # 16-bit colors in strided channels (laspy's) go the same way, scaled to 8 bits.
    wide = colors.astype(np.uint16) * 257
    image16 = pointrast.render(xyz, wide, width=W, height=H, method=method)
    assert np.array_equal(image16, image)
