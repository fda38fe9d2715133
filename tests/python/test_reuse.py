# A Renderer given new arrays (set_scene) uploads them into the GPU memory of the cloud it drew before:
# the frames equal fresh renders of the new arrays, and the reuse allocates nothing.
import numpy as np
import pytest

import pointrast

W, H = 128, 96
N = 40_000
CAMERA = pointrast.Camera((0.0, 0.0, 20.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 60.0)


def box(seed, n, z, half):
    """n points with x, y in [-half, half] and z in [z, z + 1], random uint8 colors."""
    rng = np.random.default_rng(seed)
    xyz = rng.uniform(-1, 1, (n, 3)) * [half, half, 0.5] + [0, 0, z + 0.5]
    return xyz.astype(np.float32), rng.integers(0, 256, (n, 3), dtype=np.uint8)


@pytest.mark.parametrize("method", ["atomicmin", "batch-prefetch"])
def test_new_arrays_reuse_the_gpu_memory_and_draw_only_the_new_points(method):
    # The first cloud lies in front of the others: an old point drawn after the switch would show.
    a = box(1, N, 5, 5)
    r = pointrast.Renderer(*a, camera=CAMERA, width=W, height=H, method=method)
    first = r.render()
    assert first.upload_steps_cpu_s["allocated_bytes"] >= N * 16
    for seed, n in ((2, N), (3, N * 6 // 10 + 3)):  # other points of the same size, then a smaller cloud
        b = box(seed, n, 0, 8)
        r.set_scene(*b)
        frame = r.render()
        fresh = pointrast.Renderer(*b, camera=CAMERA, width=W, height=H, method=method).render()
        assert fresh.upload_steps_cpu_s["allocated_bytes"] >= n * 16
        assert not np.array_equal(fresh.image, first.image)
        assert np.array_equal(frame.image, fresh.image), "n=%d" % n
        steps = frame.upload_steps_cpu_s
        assert frame.upload_s > 0
        assert steps["allocated_bytes"] == 0 and steps["reused_bytes"] >= n * 16
        assert steps["allocate_wall"] < max(0.01, fresh.upload_steps_cpu_s["allocate_wall"])
        assert frame.points == n


def test_a_larger_cloud_allocates_and_draws_like_a_fresh_one():
    r = pointrast.Renderer(*box(4, N // 4, 5, 5), camera=CAMERA, width=W, height=H)
    r.render()
    big = box(5, N, 0, 8)
    r.set_scene(*big)
    frame = r.render()
    assert frame.upload_steps_cpu_s["allocated_bytes"] >= N * 16
    assert np.array_equal(frame.image, pointrast.render(*big, camera=CAMERA, width=W, height=H))
