# pointrast.Renderer: one device and upload for many frames, camera helpers, picking.
import numpy as np
import pytest

import pointrast

W, H = 128, 96


def grid_cloud():
    """A flat 100 x 100 grid of points, colored by position, 1 unit apart."""
    i, j = np.meshgrid(np.arange(100), np.arange(100), indexing="ij")
    xyz = np.stack([i.ravel(), j.ravel(), np.zeros(i.size)], 1).astype(np.float64)
    colors = np.stack([i.ravel() * 2, j.ravel() * 2, np.full(i.size, 200)], 1).astype(np.uint8)
    return xyz, colors


def test_renderer_equals_render():
    xyz, colors = grid_cloud()
    r = pointrast.Renderer(xyz, colors, width=W, height=H)
    assert r.device
    frame = r.render()
    assert np.array_equal(frame.image, pointrast.render(xyz, colors, width=W, height=H))
    # the camera helpers move the view, and the overview comes back
    overview = r.camera
    r.orbit(90)
    turned = r.render()
    assert not np.array_equal(turned.image, frame.image)
    assert np.allclose(np.linalg.norm(np.subtract(r.camera.eye, r.camera.target)),
                       np.linalg.norm(np.subtract(overview.eye, overview.target)))
    r.orbit(-90)
    assert np.allclose(r.camera.eye, overview.eye)
    r.overview()
    assert np.array_equal(r.render().image, frame.image)
    r.look_at((50, 50, 100), (50, 50, 0), up=(0, 1, 0))
    top = r.render()
    assert np.array_equal(top.image, pointrast.render(xyz, colors, width=W, height=H,
                                                       camera=pointrast.Camera((50, 50, 100), (50, 50, 0), (0, 1, 0))))


def test_pick():
    xyz, colors = grid_cloud()
    r = pointrast.Renderer(xyz, colors, width=W, height=H)
    # from 200 units above, a pixel spans about 2.4 units of the grid: every pixel over it shows a point
    r.look_at((50.0, 50.0, 200.0), (50.0, 50.0, 0.0), up=(0, 1, 0))
    hit = r.pick(W // 2, H // 2)
    assert hit is not None
    x, y, z = hit["position"]
    assert abs(x - 50) <= 3 and abs(y - 50) <= 3 and abs(z) < 1e-6
    assert np.allclose(xyz[hit["index"]], hit["position"], rtol=0, atol=1e-6)
    assert abs(hit["depth"] - 200) < 1e-3
    # the corner sees nothing from high above the edge
    r.look_at((0.0, -500.0, 10.0), (0.0, -600.0, 10.0))
    assert r.pick(0, 0) is None
    with pytest.raises(ValueError, match="outside"):
        r.pick(W, 0)


def test_a_renderer_uploads_once_and_times_frames():
    xyz = np.random.default_rng(3).random((50_000, 3)) * [10, 10, 1]
    r = pointrast.Renderer(xyz, width=160, height=120, method="batch-prefetch")
    first = r.render()
    assert first.upload_s > 0
    again = r.render(frames=4)
    assert again.upload_s == 0 and again.gpu_ms > 0
    np.testing.assert_array_equal(first.image, again.image)
    with pytest.raises(ValueError, match="frames must be 1 to 10000"):
        r.render(frames=0)
