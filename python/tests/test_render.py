"""`treelet.render`: the image's shape and orientation, the same image from the GPU as from the
CPU runner, and every bad argument named."""
import numpy as np
import pytest

import treelet
from test_tracer import devices


def test_an_image_of_the_cornell_box_with_its_lamp_on_top():
    image = treelet.render("cornell", 40, 30, spp=8, device="cpu")
    assert image.shape == (30, 40, 3) and image.dtype == np.float32
    assert np.all(np.isfinite(image)) and image.min() >= 0
    # The lamp hangs from the ceiling: row 0 is the top of the picture.
    rows = image.mean(axis=(1, 2))
    assert rows[:10].mean() > rows[-10:].mean(), rows
    # More samples, less noise: the same scene at 4x the samples is closer to a long render.
    long = treelet.render("cornell", 40, 30, spp=128, device="cpu")
    short = [np.abs(treelet.render("cornell", 40, 30, spp=s, device="cpu") - long).mean() for s in (2, 32)]
    assert short[1] < short[0], short


def test_gpu_renders_what_the_cpu_runner_renders():
    if "gpu" not in devices():
        pytest.skip("no Vulkan adapter on this machine (CI is not set)")
    cpu = treelet.render("cornell", 32, 24, spp=8, seed=3, device="cpu")
    gpu = treelet.render("cornell", 32, 24, spp=8, seed=3, device="gpu")
    # The same paths from the same numbers: most pixels equal up to float rounding (a path whose
    # bounce a rounding turns elsewhere changes its pixel), the whole image within 3%.
    close = np.all(np.abs(cpu - gpu) <= 1e-3 * (1 + np.abs(cpu)), axis=2)
    assert close.mean() > 0.8, (close.mean(), np.abs(cpu - gpu).max())
    assert abs(cpu.mean() - gpu.mean()) < 0.03 * cpu.mean(), (cpu.mean(), gpu.mean())


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"width": 0}, ValueError, "width: at least 1"),
        ({"spp": 0}, ValueError, "spp: at least 1"),
        ({"integrator": "bdpt"}, ValueError, "integrator `bdpt`"),
        ({"sampler": "halton"}, ValueError, "sampler `halton`"),
        ({"accel": "kd"}, ValueError, "accel `kd`"),
        ({"device": "tpu"}, ValueError, "device `tpu`"),
        ({"scene": "no-such-file.obj"}, ValueError, "no-such-file.obj"),
        ({"width": -1}, OverflowError, ""),
    ],
)
def test_bad_arguments_are_named(kwargs, error, message):
    with pytest.raises(error) as e:
        treelet.render(**{"width": 8, "height": 8, "spp": 1, "device": "cpu", **kwargs})
    assert message in str(e.value)
