"""render(): the CLI's image, as arrays."""

import os
import subprocess

import numpy as np
import pytest

import arbor_rays as ar

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
CORNELL = os.path.join(ROOT, "examples", "cornell_box.xml")


def read_ppm(path):
    data = open(path, "rb").read()
    parts = data.split(maxsplit=4)
    assert parts[0] == b"P6" and parts[3] == b"255"
    w, h = int(parts[1]), int(parts[2])
    return np.frombuffer(parts[4][-w * h * 3:], np.uint8).reshape(h, w, 3)


def test_render_returns_the_radiance_and_the_8_bit_image():
    radiance, image = ar.render(CORNELL, spp=1)
    assert radiance.shape == (400, 400, 3) and radiance.dtype == np.float32
    assert image.shape == (400, 400, 3) and image.dtype == np.uint8
    # No tone map: the 8-bit image is the film (radiance over 255, a METU file's white) quantised.
    want = np.floor(np.clip(radiance.astype(np.float64) / 255.0, 0, 1) * 255 + 0.5)
    assert np.max(np.abs(want - image)) <= 1 and np.mean(want == image) > 0.999
    assert image.mean() > 10, "a black image is not a useful test"
    again, image2 = ar.render(CORNELL, camera="1", spp=1, threads=1, accel="kdtree")
    assert np.array_equal(image, image2) and np.array_equal(radiance, again)
    # Another seed, other noise (at one sample per pixel the sample is the pixel's centre).
    assert not np.array_equal(ar.render(CORNELL, spp=2, seed=7)[0], ar.render(CORNELL, spp=2)[0])


def test_render_is_the_cli_render_byte_for_byte(tmp_path):
    arbor = os.environ.get("ARBOR_BIN")
    if not arbor:
        if os.environ.get("CI") == "true":
            pytest.fail("NOT CHECKED under CI=true: ARBOR_BIN (the arbor binary) is not set")
        pytest.skip("NOT CHECKED: ARBOR_BIN (the arbor binary) is not set")
    out = tmp_path / "cli.ppm"
    subprocess.run([arbor, "render", CORNELL, "--spp", "2", "-q", "-o", str(out)], check=True)
    _, image = ar.render(CORNELL, spp=2)
    assert np.array_equal(read_ppm(out), image)


def test_render_errors_are_the_cli_messages(tmp_path):
    with pytest.raises(ValueError) as e:
        ar.render(CORNELL, camera="9")
    assert str(e.value) == f"{CORNELL}: no camera with id '9' (cameras: 1)"
    with pytest.raises(OSError):
        ar.render(str(tmp_path / "none.xml"))
    bad = tmp_path / "bad.xml"
    bad.write_text("<Scene><Cameras>")
    with pytest.raises(ValueError) as e:
        ar.render(str(bad))
    assert str(e.value).startswith(f"{bad}:1:")
    with pytest.raises(ValueError) as e:
        ar.render(CORNELL, spp=100000)
    assert "exceeds the limit" in str(e.value)
