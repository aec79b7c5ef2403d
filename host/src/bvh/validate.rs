//! An independent validator of built trees. It shares no code with the
//! builders: it recomputes primitive boxes itself and walks the tree from the
//! root with an explicit stack.
use treelet_core::geometry::buffers::{Node, Sphere};
use treelet_core::geometry::triangle::{Triangle, SHAPE_DISK, SHAPE_PARALLELOGRAM};

use crate::scene::primitives::Primitives;

/// The result of [`validate`]: empty `errors` means valid.
#[derive(Clone, Debug, Default)]
pub struct Validation {
    pub errors: Vec<String>,
}

impl Validation {
    pub fn is_valid(&self) -> bool {
        self.errors.is_empty()
    }
}

const LEAF_FLAG: u32 = 0x8000_0000;
const NO_PARENT: u32 = u32::MAX;
/// Stop collecting after this many errors.
const MAX_ERRORS: usize = 20;

fn sphere_box(s: &Sphere) -> ([f32; 3], [f32; 3]) {
    let lo = [s.center[0] - s.radius, s.center[1] - s.radius, s.center[2] - s.radius];
    let hi = [s.center[0] + s.radius, s.center[1] + s.radius, s.center[2] + s.radius];
    (lo, hi)
}

fn triangle_box(t: &Triangle) -> ([f32; 3], [f32; 3]) {
    if t.shape == SHAPE_DISK {
        // The ellipse c + x e1 + y e2 (x² + y² <= 1) reaches |(e1ₖ, e2ₖ)|
        // either side of c; a hair less here, as a GPU's square root may
        // round either way.
        let reach = |k: usize| ((t.v1[k] - t.v0[k]) as f64).hypot((t.v2[k] - t.v0[k]) as f64) * (1.0 - 1e-5);
        return ([0, 1, 2].map(|k| (t.v0[k] as f64 - reach(k)) as f32), [0, 1, 2].map(|k| (t.v0[k] as f64 + reach(k)) as f32));
    }
    let lo = [0, 1, 2].map(|k| t.v0[k].min(t.v1[k]).min(t.v2[k]));
    let hi = [0, 1, 2].map(|k| t.v0[k].max(t.v1[k]).max(t.v2[k]));
    if t.shape == SHAPE_PARALLELOGRAM {
        // The fourth corner, v1 + v2 - v0.
        let d = [0, 1, 2].map(|k| t.v1[k] + (t.v2[k] - t.v0[k]));
        return ([0, 1, 2].map(|k| lo[k].min(d[k])), [0, 1, 2].map(|k| hi[k].max(d[k])));
    }
    (lo, hi)
}

/// The box of primitive `i` (spheres first, then triangles), computed here.
pub(crate) fn primitive_box(prims: Primitives, i: usize) -> ([f32; 3], [f32; 3]) {
    match i.checked_sub(prims.spheres.len()) {
        None => sphere_box(&prims.spheres[i]),
        Some(t) => triangle_box(&prims.triangles[t]),
    }
}

fn encloses(outer_lo: &[f32; 3], outer_hi: &[f32; 3], lo: &[f32; 3], hi: &[f32; 3]) -> bool {
    (0..3).all(|k| outer_lo[k] <= lo[k] && outer_hi[k] >= hi[k])
}

/// Checks every structural invariant of a BVH over `spheres`:
/// between 1 and `2n - 1` nodes (fewer when leaves hold several
/// primitives); the root has no parent; each node is reached exactly
/// once from the root (no cycles, no sharing, nothing unreachable); parent
/// links match child links; every primitive is in exactly one leaf; each
/// internal box contains its children's boxes; each leaf box contains its
/// primitives; the root box contains the whole scene.
pub fn validate(spheres: &[Sphere], nodes: &[Node], parents: &[u32], prim_indices: &[u32]) -> Validation {
    validate_primitives(Primitives::spheres(spheres), nodes, parents, prim_indices)
}

/// [`validate`] for any primitives (boxes recomputed here, not by the builder's code).
pub fn validate_primitives(prims: Primitives, nodes: &[Node], parents: &[u32], prim_indices: &[u32]) -> Validation {
    validate_tree(prims, nodes, parents, prim_indices, false)
}

/// [`validate_primitives`] for a tree over pieces of triangles
/// (`treelet_core::construct::presplit`): as many leaf slots as pieces,
/// each primitive in one leaf or more, each leaf box meeting its
/// primitives' boxes rather than containing them, and the pieces covering
/// their triangle: points spread over each triangle (its corners, points on
/// its edges and inside, computed here in f64) each lie in the box of a
/// leaf that holds the triangle, give or take their rounding. Spheres and
/// flat shapes that are not triangles are never split: a leaf holding one
/// contains it.
pub fn validate_split(prims: Primitives, nodes: &[Node], parents: &[u32], prim_indices: &[u32]) -> Validation {
    validate_tree(prims, nodes, parents, prim_indices, true)
}

/// Points of triangle `t` as `f32`: barycentric `(i, j) / STEPS` over a grid.
pub(crate) fn triangle_points(t: &Triangle) -> Vec<[f32; 3]> {
    const STEPS: usize = 6;
    let mut out = Vec::new();
    for i in 0..=STEPS {
        for j in 0..=STEPS - i {
            // Weights from integers, so that points on an edge have a zero weight exactly.
            let (u, v, w) = (i as f64 / STEPS as f64, j as f64 / STEPS as f64, (STEPS - i - j) as f64 / STEPS as f64);
            out.push([0, 1, 2].map(|k| (t.v0[k] as f64 * w + t.v1[k] as f64 * u + t.v2[k] as f64 * v) as f32));
        }
    }
    out
}

/// Whether `p` is in the box `lo..hi`, give or take its rounding (an ulp).
pub(crate) fn holds_point(lo: &[f32; 3], hi: &[f32; 3], p: &[f32; 3]) -> bool {
    (0..3).all(|k| {
        let slack = p[k].abs() * 1.2e-7;
        lo[k] - slack <= p[k] && p[k] <= hi[k] + slack
    })
}

/// Whether a primitive is split into pieces by a split build (triangles only).
pub(crate) fn splittable(prims: Primitives, p: usize) -> bool {
    p.checked_sub(prims.spheres.len()).is_some_and(|t| prims.triangles[t].shape == 0)
}

/// The errors of primitives whose pieces, `boxes[p]` (the boxes of the
/// leaves holding `p`), do not cover them (see [`validate_split`]).
pub(crate) fn coverage_errors(prims: Primitives, boxes: &[Vec<([f32; 3], [f32; 3])>], mut err: impl FnMut(String)) {
    for (p, leaves) in boxes.iter().enumerate() {
        if leaves.is_empty() {
            continue;
        }
        if splittable(prims, p) {
            let t = &prims.triangles[p - prims.spheres.len()];
            if let Some(q) = triangle_points(t).into_iter().find(|q| !leaves.iter().any(|(lo, hi)| holds_point(lo, hi, q))) {
                err(format!("primitive {p}: its point {q:?} is in none of its {} leaves' boxes", leaves.len()));
            }
        } else {
            let (lo, hi) = primitive_box(prims, p);
            if !leaves.iter().any(|(l, h)| encloses(l, h, &lo, &hi)) {
                err(format!("primitive {p} (not a triangle) is in no leaf whose box contains it"));
            }
        }
    }
}

fn validate_tree(prims: Primitives, nodes: &[Node], parents: &[u32], prim_indices: &[u32], split: bool) -> Validation {
    let prim_box = |p: usize| match p.checked_sub(prims.spheres.len()) {
        None => sphere_box(&prims.spheres[p]),
        Some(t) => triangle_box(&prims.triangles[t]),
    };
    let mut v = Validation::default();
    let mut err = |e: String| {
        if v.errors.len() < MAX_ERRORS {
            v.errors.push(e);
        }
    };
    let n = prims.len();
    if n == 0 {
        if !nodes.is_empty() {
            err(format!("empty scene but {} nodes", nodes.len()));
        }
        return v;
    }
    // Leaf slots: one per primitive, or one per piece.
    let slots = if split { prim_indices.len().max(n) } else { n };
    if nodes.is_empty() || nodes.len() > 2 * slots - 1 {
        let what = if split { "leaf slots" } else { "primitives" };
        err(format!("{} nodes for {slots} {what} (expected 1 to {})", nodes.len(), 2 * slots - 1));
        return v;
    }
    if parents.len() != nodes.len() || prim_indices.len() != slots {
        err(format!(
            "{} parents and {} primitive indices for {} nodes",
            parents.len(),
            prim_indices.len(),
            nodes.len()
        ));
        return v;
    }
    if parents[0] != NO_PARENT {
        err(format!("root has parent {}", parents[0]));
    }
    let mut visited = vec![false; nodes.len()];
    let mut prim_seen = vec![0u32; n];
    // With pieces: the boxes of the leaves holding each primitive.
    let mut leaf_boxes: Vec<Vec<([f32; 3], [f32; 3])>> = if split { vec![Vec::new(); n] } else { Vec::new() };
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        if visited[i] {
            err(format!("node {i} reached twice (cycle or shared child)"));
            continue;
        }
        visited[i] = true;
        let node = &nodes[i];
        if node.right & LEAF_FLAG != 0 {
            let count = (node.right & !LEAF_FLAG) as usize;
            let first = node.left as usize;
            if count == 0 || first + count > slots {
                err(format!("leaf {i}: primitives {first}..{} out of 0..{slots}", first + count));
                continue;
            }
            for &p in &prim_indices[first..first + count] {
                let p = p as usize;
                if p >= n {
                    err(format!("leaf {i}: primitive index {p} out of range"));
                    continue;
                }
                prim_seen[p] += 1;
                let (lo, hi) = prim_box(p);
                if split {
                    if (0..3).any(|k| node.min[k] > hi[k] || node.max[k] < lo[k]) {
                        err(format!("leaf {i}: box {:?}..{:?} misses primitive {p}", node.min, node.max));
                    }
                    leaf_boxes[p].push((node.min, node.max));
                } else if !encloses(&node.min, &node.max, &lo, &hi) {
                    err(format!("leaf {i}: box {:?}..{:?} does not contain primitive {p}", node.min, node.max));
                }
            }
        } else {
            for child in [node.left as usize, node.right as usize] {
                if child >= nodes.len() || child == 0 {
                    err(format!("node {i}: child index {child} invalid"));
                    continue;
                }
                if parents[child] as usize != i {
                    err(format!("node {child}: parent link {} but child of {i}", parents[child]));
                }
                let c = &nodes[child];
                if !encloses(&node.min, &node.max, &c.min, &c.max) {
                    err(format!("node {i}: box does not contain child {child}'s box"));
                }
                stack.push(child);
            }
        }
    }
    if let Some(i) = visited.iter().position(|&x| !x) {
        err(format!(
            "node {i} is not reachable from the root ({} unreachable)",
            visited.iter().filter(|&&x| !x).count()
        ));
    }
    for (p, &count) in prim_seen.iter().enumerate() {
        if count == 0 || (count > 1 && !split) {
            err(format!("primitive {p} is in {count} leaves (expected {})", if split { "1 or more" } else { "exactly 1" }));
        }
    }
    if split {
        coverage_errors(prims, &leaf_boxes, &mut err);
    }
    let root = &nodes[0];
    for p in 0..n {
        let (lo, hi) = prim_box(p);
        if !encloses(&root.min, &root.max, &lo, &hi) {
            err(format!("root box does not contain primitive {p}"));
        }
    }
    v
}
