# The Filters options as keyword arguments: the same points kept and drawn as `pointrast render` with
# --clip-box, --clip-polygon, --clip-mode, --classes, --returns, --intensity, --source-ids.
import numpy as np
import pytest

import pointrast

from conftest import rgb

W, H = 256, 192


@pytest.fixture(scope="module")
def autzen(data):
    path = data / "las" / "autzen_trim.las"
    return path, pointrast.open(path)


def middle_box(cloud):
    (x0, y0, z0), (x1, y1, z1) = cloud.bounds
    return (x0 + (x1 - x0) * 0.25, y0 + (y1 - y0) * 0.2, z0 - 1, x0 + (x1 - x0) * 0.7, y0 + (y1 - y0) * 0.9, z1 + 1)


def text(values):
    return ",".join("%.17g" % v for v in values)


def test_clip_box_modes_equal_the_cli(autzen, cli):
    path, cloud = autzen
    box = middle_box(cloud)
    whole = pointrast.render(cloud, width=W, height=H)
    for mode in ("inside", "outside", "highlight"):
        image = pointrast.render(cloud, clip_box=box, clip_mode=mode, width=W, height=H)
        expected = cli(path, "--width", W, "--height", H, "--clip-box", text(box), "--clip-mode", mode)
        assert np.array_equal(rgb(image), expected), mode
        assert not np.array_equal(image, whole), mode


def test_clip_polygon_equals_the_cli(autzen, cli):
    path, cloud = autzen
    x0, y0, x1, y1 = middle_box(cloud)[0], middle_box(cloud)[1], middle_box(cloud)[3], middle_box(cloud)[4]
    polygon = [(x0, y0), (x1, y0), ((x0 + x1) / 2, y1)]
    image = pointrast.render(cloud, clip_polygon=polygon, width=W, height=H)
    flat = text([v for p in polygon for v in p])
    assert np.array_equal(rgb(image), cli(path, "--width", W, "--height", H, "--clip-polygon", flat))


def test_attribute_filters_equal_the_cli(autzen, cli):
    path, cloud = autzen
    classes = np.unique(cloud.classification)
    assert len(classes) >= 2, "the test needs a file with several classes"
    keep = [int(classes[0])]
    cases = [
        (dict(classes=keep), ("--classes", str(keep[0]))),
        (dict(returns="first"), ("--returns", "first")),
        (dict(intensity_range=(0, int(np.median(cloud.intensity)))),
         ("--intensity", "0,%d" % int(np.median(cloud.intensity)))),
    ]
    whole = pointrast.render(cloud, width=W, height=H)
    for kwargs, flags in cases:
        image = pointrast.render(cloud, width=W, height=H, **kwargs)
        assert np.array_equal(rgb(image), cli(path, "--width", W, "--height", H, *flags)), kwargs
    assert not np.array_equal(pointrast.render(cloud, width=W, height=H, classes=keep), whole)
    # The cloud itself is untouched: a render without filters is the whole cloud again.
    assert np.array_equal(pointrast.render(cloud, width=W, height=H), whole)


def test_a_renderer_keeps_the_filtered_upload(autzen):
    _, cloud = autzen
    r = pointrast.Renderer(cloud, width=W, height=H, classes=[2])
    first = r.render()
    again = r.render()
    assert first.upload_s > 0 and again.upload_s == 0
    assert np.array_equal(first.image, again.image)
    assert r.render(classes=None).upload_s > 0  # another set of points: uploaded again


def test_bad_filters_raise_clear_errors(autzen, data):
    _, cloud = autzen
    with pytest.raises(ValueError, match="clip_box must be"):
        pointrast.render(cloud, clip_box=(1, 2, 3), width=W, height=H)
    with pytest.raises(ValueError, match="clip_mode must be"):
        pointrast.render(cloud, clip_box=middle_box(cloud), clip_mode="around", width=W, height=H)
    with pytest.raises(ValueError, match="returns must be"):
        pointrast.render(cloud, returns="second", width=W, height=H)
    with pytest.raises(ValueError, match="classes are classification values"):
        pointrast.render(cloud, classes=[300], width=W, height=H)
    with pytest.raises(ValueError, match="clip_polygon needs at least three"):
        pointrast.render(cloud, clip_polygon=[(0, 0), (1, 1)], width=W, height=H)
    xyz = np.random.default_rng(2).random((1000, 3))
    with pytest.raises(ValueError, match="classification"):
        pointrast.render(xyz, classes=[2], width=W, height=H)  # the array has no classes
    octree = pointrast.open(data / "laz" / "lone-star.copc.laz")
    with pytest.raises(ValueError, match="clip volumes only"):
        pointrast.render(octree, classes=[2], width=W, height=H)


def test_an_octree_clipped_equals_the_cli(data, cli):
    path = data / "laz" / "lone-star.copc.laz"
    octree = pointrast.open(path)
    box = middle_box(octree)
    whole = pointrast.render(octree, width=W, height=H)
    image = pointrast.render(octree, clip_box=box, width=W, height=H)
    assert np.array_equal(rgb(image), cli(path, "--method", "lod", "--width", W, "--height", H, "--clip-box",
                                          text(box)))
    assert not np.array_equal(image, whole)
