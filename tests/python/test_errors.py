# Bad input raises a clear Python exception: the dtype TypeError, the rest ValueError with the sentence.
import numpy as np
import pytest

import pointrast

XYZ = np.random.default_rng(3).random((1000, 3))


@pytest.mark.parametrize("xyz, error, words", [
    (np.zeros((10, 2)), ValueError, "shape (N, 3), not (10, 2)"),
    (np.zeros(30), ValueError, "shape (N, 3), not (30,)"),
    (np.zeros((10, 3), np.int32), TypeError, "float32 or float64, not int32"),
    (np.zeros((10, 3), np.float16), TypeError, "float32 or float64, not float16"),
    (np.asfortranarray(np.zeros((10, 3))), ValueError, "C-contiguous"),
    (np.zeros((10, 6))[:, ::2], ValueError, "C-contiguous"),
])
def test_bad_arrays(xyz, error, words):
    with pytest.raises(error) as e:
        pointrast.render(xyz, width=16, height=16)
    assert words in str(e.value)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_not_finite(value):
    xyz = XYZ.copy()
    xyz[17, 1] = value
    with pytest.raises(ValueError, match="xyz row 17 is not finite"):
        pointrast.render(xyz, width=16, height=16)


def test_bad_colors():
    with pytest.raises(TypeError, match="red must be uint8 or uint16, not float64"):
        pointrast.render(XYZ, np.zeros((1000, 3)), width=16, height=16)
    with pytest.raises(ValueError, match="red has 10 values for 1000 points"):
        pointrast.render(XYZ, np.zeros((10, 3), np.uint8), width=16, height=16)
    with pytest.raises(ValueError, match=r"colors must be \(N, 3\)"):
        pointrast.render(XYZ, np.zeros((1000, 4), np.uint8), width=16, height=16)


def test_bad_options():
    with pytest.raises(ValueError, match="unknown method 'nope'|nope"):
        pointrast.render(XYZ, width=16, height=16, method="nope")
    with pytest.raises(ValueError, match="width and height must be at least 1"):
        pointrast.render(XYZ, width=0, height=16)
    with pytest.raises(TypeError, match="unknown render option"):
        pointrast.render(XYZ, width=16, height=16, pointsize=3)
    with pytest.raises(ValueError, match="square or disc|point shape|shape"):
        pointrast.render(XYZ, width=16, height=16, point_shape="star")
    with pytest.raises(ValueError, match="intensity"):
        pointrast.render(XYZ, width=16, height=16, color="intensity")  # the array has no intensity
    with pytest.raises(ValueError, match="octree"):
        pointrast.render(XYZ, width=16, height=16, method="lod")
    with pytest.raises(ValueError, match="LOD methods"):
        pointrast.render(XYZ, width=16, height=16, min_node_px=10)


def test_bad_cameras():
    with pytest.raises(ValueError, match="camera"):
        pointrast.render(XYZ, width=16, height=16, camera={"eye": (0.5, 0.5, 0.5), "target": (0.5, 0.5, 0.5)})
    with pytest.raises(ValueError, match="camera eye must be three numbers"):
        pointrast.render(XYZ, width=16, height=16, camera={"eye": (1, 2)})
    with pytest.raises(ValueError, match="fov"):
        pointrast.render(XYZ, width=16, height=16, camera={"fov": 180})
    with pytest.raises(TypeError, match="camera must be"):
        pointrast.render(XYZ, width=16, height=16, camera=(1, 2, 3))


def test_bad_inputs(tmp_path):
    with pytest.raises(TypeError, match="render\\(\\) takes"):
        pointrast.render([[0, 0, 0]], width=16, height=16)
    with pytest.raises(FileNotFoundError):
        pointrast.open(tmp_path / "missing.las")
    bad = tmp_path / "bad.las"
    bad.write_bytes(b"LASF" + b"\0" * 50)
    with pytest.raises(ValueError, match="bad.las"):
        pointrast.open(bad)
