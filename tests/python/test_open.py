# pointrast.open(): clouds read whole, octrees (Potree 2.0, COPC) drawn with level of detail, like the CLI.
import numpy as np
import pytest

import pointrast

from conftest import rgb

W, H = 200, 150


def test_open_las_attributes(data):
    cloud = pointrast.open(data / "las" / "autzen_trim.las")
    assert len(cloud) == len(cloud.x) == len(cloud.X)
    assert np.allclose(cloud.x, cloud.X * cloud.header.scales[0] + cloud.header.offsets[0])
    lo, hi = cloud.bounds
    assert lo[2] == cloud.z.min() and hi[2] == cloud.z.max()
    assert cloud.red.dtype == np.uint8 and cloud.intensity is not None
    assert cloud.xyz.shape == (len(cloud), 3)


@pytest.mark.parametrize("octree", ["potree/autzen_trim_default", "potree/autzen_trim_brotli",
                                    "laz/lone-star.copc.laz"])
def test_octree_lod_equals_cli(data, cli, octree):
    path = data / octree
    tree = pointrast.open(path)
    assert isinstance(tree, pointrast.Octree) and tree.point_count > 0
    image = pointrast.render(tree, width=W, height=H, min_node_px=50)
    assert np.array_equal(rgb(image), cli(path, "--method", "lod", "--width", W, "--height", H, "--min-node-px", 50))
    full = pointrast.render(tree, width=W, height=H, min_node_px=0)
    assert (rgb(full).sum(axis=2) > 0).sum() >= (rgb(image).sum(axis=2) > 0).sum()


def test_copc_as_cloud(data, cli):
    path = data / "laz" / "lone-star.copc.laz"
    cloud = pointrast.open(path, lod=False)
    assert isinstance(cloud, pointrast.Cloud)
    assert np.array_equal(rgb(pointrast.render(cloud, width=W, height=H)), cli(path, "--width", W, "--height", H))


def test_octree_renderer(data):
    tree = pointrast.open(data / "potree" / "autzen_trim_default")
    r = pointrast.Renderer(tree, width=W, height=H, min_node_px=50)
    first = r.render()
    assert first.method == "lod"
    assert np.array_equal(r.render().image, first.image)
    r.orbit(45, 10)
    assert not np.array_equal(r.render().image, first.image)
