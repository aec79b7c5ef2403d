//! One build, run and summarized: what `treelet build` prints.
use std::time::Instant;

use anyhow::Result;
use serde::Serialize;
use treelet_core::sah::{sah_cost, SahCosts};

use crate::backend::Backend;
use crate::lbvh::{self, Bvh, STAGES};
use crate::scene::{validate_spheres, Scene};
use crate::validate::validate;

#[derive(Clone, Debug, Serialize)]
pub struct BuildReport {
    pub scene: String,
    pub primitives: usize,
    pub builder: &'static str,
    pub device: &'static str,
    pub adapter: String,
    pub nodes: usize,
    /// SAH with C_i = 1.2 per node, C_t = 1 per primitive (Karras & Aila 2013).
    pub sah_cost: f64,
    pub valid: bool,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<String>,
    /// Sum of the stage times.
    pub total_ms: f64,
    /// Wall-clock time of the whole call, uploads and readbacks included.
    pub wall_ms: f64,
    pub ms: serde_json::Map<String, serde_json::Value>,
    /// "gpu-timestamps" or "wall-clock".
    pub timing: &'static str,
}

/// The full-sweep SAH reference build (CPU only), reported like the others.
pub fn run_build_sweep(scene: &Scene) -> Result<(Bvh, BuildReport)> {
    let objects = scene.objects();
    validate_spheres(objects)?;
    let start = Instant::now();
    let bvh = crate::sweep::build(objects);
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let check = validate(objects, &bvh.nodes, &bvh.parents, &bvh.prim_indices);
    let mut ms = serde_json::Map::new();
    ms.insert("sweep".into(), serde_json::json!(wall_ms));
    let report = BuildReport {
        scene: scene.name.clone(),
        primitives: objects.len(),
        builder: "sweep",
        device: "cpu",
        adapter: "cpu".into(),
        nodes: bvh.nodes.len(),
        sah_cost: sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA),
        valid: check.is_valid(),
        errors: check.errors,
        total_ms: wall_ms,
        wall_ms,
        ms,
        timing: "wall-clock",
    };
    Ok((bvh, report))
}

/// Validates the input, builds, validates the tree, and reports.
pub fn run_build<B: Backend>(backend: &mut B, scene: &Scene) -> Result<(Bvh, BuildReport)> {
    let objects = scene.objects();
    validate_spheres(objects)?;
    let start = Instant::now();
    let (bvh, times) = lbvh::build(backend, objects)?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let check = validate(objects, &bvh.nodes, &bvh.parents, &bvh.prim_indices);
    let ms = STAGES.iter().map(|s| (s.to_string(), serde_json::json!(times.get(s)))).collect();
    let report = BuildReport {
        scene: scene.name.clone(),
        primitives: objects.len(),
        builder: "lbvh",
        device: backend.device_kind(),
        adapter: backend.adapter(),
        nodes: bvh.nodes.len(),
        sah_cost: sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA),
        valid: check.is_valid(),
        errors: check.errors,
        total_ms: times.total(),
        wall_ms,
        ms,
        timing: if times.source.is_empty() { "wall-clock" } else { times.source },
    };
    Ok((bvh, report))
}
