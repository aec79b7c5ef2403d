//! `treelet.render`: a scene path traced on a device, as `treelet render`
//! does, returned as an HDR image.
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use treelet::bvh::layout::Layout;
use treelet::bvh::tree::Accel;
use treelet::render::run::render as render_scene;
use treelet::render::settings::{Integrator, RenderSettings, Sampler};
use treelet::render::variant::KernelChoice;
use treelet::scene::Scene;

use crate::device::{self, on_device};

/// Renders `scene` (what `treelet render --scene` takes: "cornell",
/// "room_disk", "terrain:N", "city:N", a .json scene file, a .gltf/.glb
/// scene or an .obj/.ply mesh) at `width` x `height` with `spp` samples per
/// pixel, and returns the linear HDR image as a (height, width, 3) float32
/// array, row 0 at the top. `integrator`: "nee" (next-event estimation with
/// MIS), "smallpt" or "caustics"; `sampler`: "sobol" or "independent";
/// `accel`: "auto", "none", "lbvh", "hploc" or "trbvh"; `device` as for
/// `Tracer`. On a GPU the GIL is released while it renders.
///
/// >>> import treelet
/// >>> image = treelet.render("cornell", 32, 24, spp=4, device="cpu")
/// >>> image.shape, bool(image.mean() > 0)
/// ((24, 32, 3), True)
#[pyfunction]
#[pyo3(signature = (scene = "cornell", width = 512, height = 384, spp = 16, seed = 0, integrator = "nee", sampler = "sobol", accel = "auto", device = "auto"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn render<'py>(
    py: Python<'py>,
    scene: &str,
    width: u32,
    height: u32,
    spp: u32,
    seed: u32,
    integrator: &str,
    sampler: &str,
    accel: &str,
    device: &str,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    for (what, v) in [("width", width), ("height", height), ("spp", spp)] {
        if v == 0 {
            return Err(PyValueError::new_err(format!("{what}: at least 1")));
        }
    }
    let integrator = match integrator {
        "nee" => Integrator::Nee,
        "smallpt" => Integrator::Smallpt,
        "caustics" => Integrator::Caustics,
        other => return Err(PyValueError::new_err(format!("integrator `{other}`: use nee, smallpt or caustics"))),
    };
    let sampler = match sampler {
        "sobol" => Sampler::Sobol,
        "independent" => Sampler::Independent,
        other => return Err(PyValueError::new_err(format!("sampler `{other}`: use sobol or independent"))),
    };
    let accel = match accel {
        "auto" => Accel::Auto,
        "none" => Accel::None,
        "lbvh" => Accel::Lbvh,
        "hploc" => Accel::Hploc,
        "trbvh" => Accel::Trbvh,
        other => return Err(PyValueError::new_err(format!("accel `{other}`: use auto, none, lbvh, hploc or trbvh"))),
    };
    let scene = Scene::from_spec(scene).map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    let settings = RenderSettings {
        width,
        height,
        spp,
        seed,
        accel,
        layout: Layout::Auto,
        kernel: KernelChoice::Auto,
        integrator,
        sampler,
        error_each_pass: false,
        first_sample: 0,
    };
    let mut opened = device::open(device)?;
    let result = on_device!(&mut opened, py, |b, _t| render_scene(b, &scene, &settings, None, |_| {}))
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("{e:#}")))?;
    let pixels: Vec<f32> = result.image.pixels.iter().flatten().copied().collect();
    let image = Array3::from_shape_vec((height as usize, width as usize, 3), pixels).expect("height rows of width pixels");
    Ok(image.into_pyarray(py))
}
