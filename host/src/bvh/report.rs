//! One build, run and summarized: what `treelet build` prints.
use std::time::Instant;

use anyhow::Result;
use serde::Serialize;
use treelet_core::construct::sah::{SahCosts, sah_cost};

use crate::runtime::backend::Backend;
use treelet_core::{Aabb, Node};

use crate::bvh::epo::epo;
use crate::bvh::lbvh::{self, Bvh, STAGES};
use crate::bvh::trbvh::{self, TreeletConfig};
use crate::bvh::tree::Builder;
use crate::bvh::validate::validate_primitives;
use crate::scene::Scene;

#[derive(Clone, Debug, Serialize)]
pub struct BuildReport {
    pub scene: String,
    pub primitives: usize,
    /// Of which spheres and triangles.
    pub spheres: usize,
    pub triangles: usize,
    pub builder: &'static str,
    pub device: &'static str,
    pub adapter: String,
    pub nodes: usize,
    /// SAH with C_i = 1.2 per node, C_t = 1 per primitive (Karras & Aila 2013).
    pub sah_cost: f64,
    /// End-point overlap with the same constants ([`crate::bvh::epo`]): on
    /// scenes of mixed triangle sizes, a better predictor of trace speed.
    /// `None` (JSON `null`) where the triangles overlap too many boxes for
    /// it to be counted in bounded time.
    pub epo: Option<f64>,
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
    /// Leaves of the tree (fewer than the primitives after a leaf collapse).
    pub leaves: usize,
    /// Leaf slots: the primitives, or more where triangles were split into
    /// pieces (`TREELET_SPLITS`, see `treelet_core::construct::presplit`).
    pub references: usize,
    /// Largest leaf the SAH collapse may make (trbvh, sweep).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_leaf: Option<u32>,
    /// Treelet optimization (builder `trbvh`): its settings, the SAH before
    /// and after, and the time of each round (ms).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rounds: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gamma: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sah_before: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sah_after: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub round_ms: Option<Vec<f64>>,
    /// Every stage of the rounds in order, with `TREELET_PROFILE_LEVELS`
    /// (each height of each round a stage of its own), for profiling.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stage_ms: Option<Vec<(String, f64)>>,
}

/// A CPU build (`sweep`, or `reference`: the quality reference), its
/// leaves collapsed by SAH, reported like the others.
pub fn run_build_cpu(scene: &Scene, builder: Builder, max_leaf: u32) -> Result<(Bvh, BuildReport)> {
    let prims = scene.primitives();
    prims.check()?;
    let start = Instant::now();
    let tree = match builder {
        Builder::Sweep => crate::bvh::sweep::build_boxes(&prims.boxes()),
        Builder::Reference => crate::bvh::reference::build_boxes(&prims.boxes())?.0,
        _ => anyhow::bail!("internal: {} is a device builder", builder.name()),
    };
    let bvh = crate::bvh::sweep::collapse(tree, max_leaf)?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let check = validate_primitives(prims, &bvh.nodes, &bvh.parents, &bvh.prim_indices);
    let mut ms = serde_json::Map::new();
    ms.insert(builder.name().into(), serde_json::json!(wall_ms));
    let report = BuildReport {
        scene: scene.name.clone(),
        primitives: prims.len(),
        spheres: prims.counts().0,
        triangles: prims.counts().1,
        builder: builder.name(),
        device: "cpu",
        adapter: "cpu".into(),
        nodes: bvh.nodes.len(),
        sah_cost: sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA),
        epo: epo(prims, &bvh.nodes, &bvh.parents, &bvh.prim_indices, SahCosts::KARRAS_AILA),
        valid: check.is_valid(),
        errors: check.errors,
        total_ms: wall_ms,
        wall_ms,
        ms,
        timing: "wall-clock",
        leaves: leaf_count(&bvh.nodes),
        references: bvh.prim_indices.len(),
        max_leaf: Some(max_leaf),
        rounds: None,
        gamma: None,
        sah_before: None,
        sah_after: None,
        round_ms: None,
        stage_ms: None,
    };
    Ok((bvh, report))
}

/// Validates the input, builds (LBVH, then treelet rounds when `treelets`
/// is given), validates the tree, and reports.
pub fn run_build<B: Backend>(
    backend: &mut B,
    scene: &Scene,
    treelets: Option<&TreeletConfig>,
) -> Result<(Bvh, BuildReport)> {
    run_build_with(backend, scene, if treelets.is_some() { Builder::Trbvh } else { Builder::Lbvh }, treelets.cloned().unwrap_or_default())
}

/// [`run_build`] for a device builder (`lbvh`; `trbvh` with `config`'s
/// rounds; `hploc`, with `config`'s rounds if any), whose leaves are
/// collapsed by SAH as for tracing (`trbvh`, `hploc`, up to
/// `config.max_leaf` primitives).
pub fn run_build_with<B: Backend>(
    backend: &mut B,
    scene: &Scene,
    builder: Builder,
    config: TreeletConfig,
) -> Result<(Bvh, BuildReport)> {
    // Treelet rounds: the TRBVH's, or over the H-PLOC tree where asked.
    let config = crate::bvh::tree::settled(&config, builder, backend.class());
    let treelets = (builder == Builder::Trbvh || (builder == Builder::Hploc && (config.rounds > 0 || config.reinsert_iterations() > 0))).then_some(&config);
    let hierarchy = match builder {
        Builder::Hploc => Some(lbvh::Hierarchy::Hploc),
        Builder::Lbvh | Builder::Trbvh => None,
        Builder::Sweep | Builder::Reference => anyhow::bail!("internal: the {} builder is run by run_build_cpu", builder.name()),
    };
    let prims = scene.primitives();
    prims.check()?;
    crate::bvh::tree::check_build_memory(prims.len() as u64, backend.class())?;
    // Pipelines first, all at once: a fresh machine's driver compiles each for
    // long, and a build timed around that compile runs on a cooled-down GPU.
    let budget = crate::bvh::tree::split_budget(builder);
    let mut kernels = crate::bvh::tree::build_kernels(backend, builder, budget, &config);
    kernels.extend(match treelets {
        Some(config) => trbvh::kernels(backend, config),
        None => trbvh::collapse_kernels(backend),
    });
    backend.prepare_kernels(&kernels);
    let start = Instant::now();
    let hierarchy = hierarchy.unwrap_or_else(|| lbvh::Hierarchy::for_device(backend, prims.len()));
    let (mut device_bvh, times) = lbvh::build_primitives_split(backend, prims, hierarchy, budget)?;
    let mut bvh = device_bvh.read(backend)?;
    let mut ms: serde_json::Map<String, serde_json::Value> =
        STAGES.iter().map(|s| (s.to_string(), serde_json::json!(times.get(s)))).collect();
    let mut total_ms = times.total();
    let (mut sah_before, mut round_ms, mut stage_ms) = (None, None, None);
    if let Some(config) = treelets {
        sah_before = Some(sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA));
        let root = bvh.nodes.first().map(|n| n.aabb()).unwrap_or(Aabb::EMPTY);
        let (optimized, rounds) = trbvh::optimize(backend, device_bvh, &root, config)?;
        device_bvh = optimized;
        let per_round: Vec<f64> =
            rounds.order.iter().filter(|s| s.starts_with("round")).map(|s| rounds.get(s)).collect();
        total_ms += rounds.total();
        ms.insert("treelets".into(), serde_json::json!(per_round.iter().sum::<f64>()));
        ms.insert("collapse".into(), serde_json::json!(rounds.get("collapse")));
        if config.reinsert_iterations() > 0 {
            ms.insert("reinsert".into(), serde_json::json!(rounds.get("reinsert")));
        }
        round_ms = Some(per_round);
        if crate::tuning::Tuning::current().profile_levels.is_some() {
            stage_ms = Some(rounds.order.iter().map(|s| (s.to_string(), rounds.get(s))).collect());
        }
        bvh = device_bvh.read(backend)?;
    } else if builder != Builder::Lbvh {
        backend.take_times()?;
        backend.stage("collapse");
        device_bvh = trbvh::collapse(backend, device_bvh, config.max_leaf)?;
        let collapse = backend.take_times()?.total();
        total_ms += collapse;
        ms.insert("collapse".into(), serde_json::json!(collapse));
        bvh = device_bvh.read(backend)?;
    }
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    // A tree over pieces of triangles has more leaf slots than primitives.
    let check = if bvh.prim_indices.len() == prims.len() && budget == 0.0 {
        validate_primitives(prims, &bvh.nodes, &bvh.parents, &bvh.prim_indices)
    } else {
        crate::bvh::validate::validate_split(prims, &bvh.nodes, &bvh.parents, &bvh.prim_indices)
    };
    if times.get("split") > 0.0 {
        ms.insert("split".into(), serde_json::json!(times.get("split")));
    }
    let sah = sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA);
    let report = BuildReport {
        scene: scene.name.clone(),
        primitives: prims.len(),
        spheres: prims.counts().0,
        triangles: prims.counts().1,
        builder: builder.name(),
        device: backend.device_kind(),
        adapter: backend.adapter(),
        nodes: bvh.nodes.len(),
        sah_cost: sah,
        epo: epo(prims, &bvh.nodes, &bvh.parents, &bvh.prim_indices, SahCosts::KARRAS_AILA),
        valid: check.is_valid(),
        errors: check.errors,
        total_ms,
        wall_ms,
        ms,
        timing: if times.source.is_empty() { "wall-clock" } else { times.source },
        leaves: leaf_count(&bvh.nodes),
        references: bvh.prim_indices.len(),
        max_leaf: (builder != Builder::Lbvh).then_some(config.max_leaf),
        rounds: treelets.map(|c| c.rounds),
        gamma: treelets.map(|c| c.gamma),
        sah_before,
        sah_after: sah_before.map(|_| sah),
        round_ms,
        stage_ms,
    };
    Ok((bvh, report))
}

fn leaf_count(nodes: &[Node]) -> usize {
    nodes.iter().filter(|n| n.is_leaf()).count()
}
