//! An independent validator of the traversal layouts (`bvh2`, `cwbvh`):
//! like [`crate::bvh::validate`], it shares no code with the kernels that make
//! them. It decodes every node itself, recomputes each subtree's exact box
//! from its primitives, and checks, in exact arithmetic, that the box a
//! node stores for each child (for cwbvh, the dequantized bytes) contains
//! it; that every primitive is stored exactly once and exactly as the scene
//! has it; and that every node is reached exactly once from the root.
use treelet_core::geometry::buffers::{Bvh2Node, Bvh4Node, LeafPrim, WideNode};

use crate::bvh::validate::{primitive_box, Validation};
use crate::scene::primitives::Primitives;

/// Stop collecting after this many errors.
const MAX_ERRORS: usize = 20;

type Box3 = ([f32; 3], [f32; 3]);

fn union(a: Box3, b: Box3) -> Box3 {
    ([0, 1, 2].map(|k| a.0[k].min(b.0[k])), [0, 1, 2].map(|k| a.1[k].max(b.1[k])))
}

const EMPTY: Box3 = ([f32::MAX; 3], [-f32::MAX; 3]);

fn intersect(a: Box3, b: Box3) -> Box3 {
    ([0, 1, 2].map(|k| a.0[k].max(b.0[k])), [0, 1, 2].map(|k| a.1[k].min(b.1[k])))
}

/// Collects errors and the primitives seen.
struct Check<'a> {
    prims: Primitives<'a>,
    v: Validation,
    seen_prim: Vec<u32>,
    /// A tree over pieces of triangles: the boxes of the leaves holding
    /// each primitive (see [`crate::bvh::validate::validate_split`]).
    pieces: Option<Vec<Vec<Box3>>>,
}

impl<'a> Check<'a> {
    fn new(prims: Primitives<'a>, split: bool) -> Self {
        let pieces = split.then(|| vec![Vec::new(); prims.len()]);
        Check { prims, v: Validation::default(), seen_prim: vec![0; prims.len()], pieces }
    }

    /// With pieces, a leaf's own box stands for its primitives' (which it
    /// need not contain): the leaf `slots` of `stored` are recorded for the
    /// coverage check, and `stored` is what the nodes above must contain.
    fn leaf_of_pieces(&mut self, leaf_prims: &[LeafPrim], slots: std::ops::Range<u32>, stored: Box3, at: &str) -> Box3 {
        for slot in slots {
            self.leaf(leaf_prims, slot as usize, at);
            if let (Some(pieces), Some(p)) = (self.pieces.as_mut(), leaf_prims.get(slot as usize)) {
                if let Some(list) = pieces.get_mut(p.prim as usize) {
                    list.push(stored);
                }
            }
        }
        stored
    }

    fn err(&mut self, e: String) {
        if self.v.errors.len() < MAX_ERRORS {
            self.v.errors.push(e);
        }
    }

    /// The exact box of leaf primitive `slot`, after checking that it is the
    /// scene's primitive, stored unchanged, and counting it.
    fn leaf(&mut self, leaf_prims: &[LeafPrim], slot: usize, at: &str) -> Box3 {
        let Some(p) = leaf_prims.get(slot) else {
            self.err(format!("{at}: leaf primitive {slot} out of range ({})", leaf_prims.len()));
            return EMPTY;
        };
        let i = p.prim as usize;
        if i >= self.prims.len() {
            self.err(format!("{at}: leaf primitive {slot} names primitive {i} of {}", self.prims.len()));
            return EMPTY;
        }
        self.seen_prim[i] += 1;
        let same = match i.checked_sub(self.prims.spheres.len()) {
            None => {
                let s = &self.prims.spheres[i];
                p.p0 == s.center && p.p1[0] == s.radius
            }
            Some(t) => {
                let t = &self.prims.triangles[t];
                p.p0 == t.v0 && p.p1 == t.v1 && p.p2 == t.v2 && p.shape == t.shape
            }
        };
        if !same {
            self.err(format!("{at}: leaf primitive {slot} does not hold primitive {i} as the scene has it"));
        }
        primitive_box(self.prims, i)
    }

    fn finish(mut self) -> Validation {
        let split = self.pieces.is_some();
        for (i, &c) in self.seen_prim.clone().iter().enumerate() {
            if c == 0 || (c > 1 && !split) {
                self.err(format!("primitive {i} is stored {c} times"));
            }
        }
        if let Some(pieces) = self.pieces.take() {
            let mut errors = Vec::new();
            crate::bvh::validate::coverage_errors(self.prims, &pieces, |e| errors.push(e));
            for e in errors {
                self.err(e);
            }
        }
        self.v
    }
}

/// `a - b` in f64 as an unevaluated sum `(s, e)`, exactly (two-sum).
fn exact_difference(a: f64, b: f64) -> (f64, f64) {
    let s = a - b;
    let bb = s - a;
    (s, (a - (s - bb)) + (-b - bb))
}

/// Whether `origin + q s <= x` exactly (`q s` is exact in f64).
fn plane_at_most(origin: f32, q: u32, s: f64, x: f32) -> bool {
    let v = q as f64 * s;
    let (d, e) = exact_difference(x as f64, origin as f64);
    v < d || (v == d && e >= 0.0)
}

/// Whether `origin + q s >= x` exactly.
fn plane_at_least(origin: f32, q: u32, s: f64, x: f32) -> bool {
    let v = q as f64 * s;
    let (d, e) = exact_difference(x as f64, origin as f64);
    v > d || (v == d && e <= 0.0)
}

/// Checks a compressed wide BVH (root 0) over `prims`; see the module doc.
/// Also checks each node's encoding: meta bytes of empty, internal and leaf
/// slots, the internal-child mask, leaves of 1 to 3 primitives within the
/// node's 24.
pub fn validate_wide(prims: Primitives, nodes: &[WideNode], leaf_prims: &[LeafPrim]) -> Validation {
    validate_wide_tree(prims, nodes, leaf_prims, false)
}

/// [`validate_wide`] for a tree over pieces of triangles: see
/// [`crate::bvh::validate::validate_split`] (a leaf's dequantized box
/// stands for its pieces).
pub fn validate_wide_split(prims: Primitives, nodes: &[WideNode], leaf_prims: &[LeafPrim]) -> Validation {
    validate_wide_tree(prims, nodes, leaf_prims, true)
}

fn validate_wide_tree(prims: Primitives, nodes: &[WideNode], leaf_prims: &[LeafPrim], split: bool) -> Validation {
    let mut c = Check::new(prims, split);
    if nodes.is_empty() {
        c.err("no nodes".into());
        return c.finish();
    }
    let mut seen_node = vec![0u32; nodes.len()];
    let everywhere = ([f32::MIN; 3], [f32::MAX; 3]);
    let root = wide_box(&mut c, nodes, leaf_prims, 0, &mut seen_node, 0, everywhere);
    let _ = root;
    for (i, &s) in seen_node.iter().enumerate() {
        if s != 1 {
            c.err(format!("node {i} reached {s} times"));
        }
    }
    c.finish()
}

/// The exact box of wide node `i`'s subtree, checking it on the way.
/// `clip`: the common part of the boxes of the slots on the way down, where
/// a ray must pass to reach this node (with pieces of triangles, what a
/// leaf's pieces must cover; see [`Check::leaf_of_pieces`]).
fn wide_box(c: &mut Check, nodes: &[WideNode], leaf_prims: &[LeafPrim], i: usize, seen: &mut [u32], depth: u32, clip: Box3) -> Box3 {
    let Some(node) = nodes.get(i) else {
        c.err(format!("node index {i} out of range ({})", nodes.len()));
        return EMPTY;
    };
    seen[i] += 1;
    if seen[i] > 1 || depth > 64 {
        return EMPTY;
    }
    let byte = |w: &[u32; 2], slot: usize| (w[slot / 4] >> (8 * (slot % 4))) & 0xFF;
    let exps = [node.exp_imask & 0xFF, (node.exp_imask >> 8) & 0xFF, (node.exp_imask >> 16) & 0xFF];
    let imask = node.exp_imask >> 24;
    let mut total = EMPTY;
    let mut internal_rank = 0usize;
    let mut prims_used = 0u32;
    for slot in 0..8 {
        let at = format!("node {i} slot {slot}");
        let meta = byte(&node.meta, slot);
        let internal = imask >> slot & 1 == 1;
        if meta == 0 {
            if internal {
                c.err(format!("{at}: empty, but marked internal"));
            }
            continue;
        }
        let exact = if internal {
            if meta != 0b001_00000 | (24 + slot as u32) {
                c.err(format!("{at}: internal child with meta {meta:#010b}"));
            }
            let child = node.child_base as usize + internal_rank;
            internal_rank += 1;
            let inner = intersect(clip, dequantized(node, slot, &exps));
            wide_box(c, nodes, leaf_prims, child, seen, depth + 1, inner)
        } else {
            let count = match meta >> 5 {
                0b001 => 1,
                0b011 => 2,
                0b111 => 3,
                other => {
                    c.err(format!("{at}: leaf count bits {other:#05b}"));
                    0
                }
            };
            let offset = meta & 0x1F;
            if offset + count > 24 {
                c.err(format!("{at}: leaf primitives {offset}..{} past the node's 24", offset + count));
            }
            prims_used += count;
            let first = node.prim_base + offset;
            if c.pieces.is_some() {
                // Where a ray reaches these pieces: every box on the way.
                let reach = intersect(clip, dequantized(node, slot, &exps));
                c.leaf_of_pieces(leaf_prims, first..first + count, reach, &at)
            } else {
                let mut b = EMPTY;
                for k in 0..count {
                    b = union(b, c.leaf(leaf_prims, (first + k) as usize, &at));
                }
                b
            }
        };
        // The dequantized box must contain the exact one. (With pieces,
        // leaves stand for themselves by the boxes on their way down, the
        // `clip` above, and the coverage check replaces this one.)
        if c.pieces.is_some() {
            total = union(total, exact);
            continue;
        }
        let q = [
            (byte(&node.lo_x, slot), byte(&node.hi_x, slot)),
            (byte(&node.lo_y, slot), byte(&node.hi_y, slot)),
            (byte(&node.lo_z, slot), byte(&node.hi_z, slot)),
        ];
        for k in 0..3 {
            if exps[k] == 0 || exps[k] == 255 {
                c.err(format!("node {i}: exponent byte {} on axis {k}", exps[k]));
                continue;
            }
            let s = 2f64.powi(exps[k] as i32 - 127);
            if !plane_at_most(node.origin[k], q[k].0, s, exact.0[k]) || !plane_at_least(node.origin[k], q[k].1, s, exact.1[k]) {
                c.err(format!(
                    "{at}: quantized box {}..{} on axis {k} does not contain {}..{}",
                    node.origin[k] as f64 + q[k].0 as f64 * s,
                    node.origin[k] as f64 + q[k].1 as f64 * s,
                    exact.0[k],
                    exact.1[k]
                ));
            }
        }
        total = union(total, exact);
    }
    if prims_used > 24 {
        c.err(format!("node {i}: {prims_used} leaf primitives, at most 24 fit"));
    }
    if internal_rank != imask.count_ones() as usize {
        c.err(format!("node {i}: internal mask {imask:#010b} and meta disagree"));
    }
    total
}

/// Slot `slot`'s box of wide node `node` as its bytes say, widened to the
/// `f32`s that hold it (the validator's own decoding).
fn dequantized(node: &WideNode, slot: usize, exps: &[u32; 3]) -> Box3 {
    let byte = |w: &[u32; 2]| (w[slot / 4] >> (8 * (slot % 4))) & 0xFF;
    let q = [(byte(&node.lo_x), byte(&node.hi_x)), (byte(&node.lo_y), byte(&node.hi_y)), (byte(&node.lo_z), byte(&node.hi_z))];
    let mut lo = [0f32; 3];
    let mut hi = [0f32; 3];
    for k in 0..3 {
        let s = 2f64.powi(exps[k] as i32 - 127);
        let (l, h) = (node.origin[k] as f64 + q[k].0 as f64 * s, node.origin[k] as f64 + q[k].1 as f64 * s);
        // Rounded outwards, so that the f32 box holds the exact one.
        lo[k] = if (l as f32) as f64 > l { (l as f32).next_down() } else { l as f32 };
        hi[k] = if ((h as f32) as f64) < h { (h as f32).next_up() } else { h as f32 };
    }
    (lo, hi)
}

/// Checks a two-box binary BVH (root 0) over `prims`; see the module doc.
pub fn validate_bvh2(prims: Primitives, nodes: &[Bvh2Node], leaf_prims: &[LeafPrim]) -> Validation {
    validate_bvh2_tree(prims, nodes, leaf_prims, false)
}

/// [`validate_bvh2`] for a tree over pieces of triangles: see
/// [`crate::bvh::validate::validate_split`] (a leaf child's stored box
/// stands for its pieces).
pub fn validate_bvh2_split(prims: Primitives, nodes: &[Bvh2Node], leaf_prims: &[LeafPrim]) -> Validation {
    validate_bvh2_tree(prims, nodes, leaf_prims, true)
}

fn validate_bvh2_tree(prims: Primitives, nodes: &[Bvh2Node], leaf_prims: &[LeafPrim], split: bool) -> Validation {
    let mut c = Check::new(prims, split);
    if nodes.is_empty() {
        c.err("no nodes".into());
        return c.finish();
    }
    let mut seen_node = vec![0u32; nodes.len()];
    // (node, depth); boxes checked against exact subtree boxes bottom up.
    fn visit(c: &mut Check, nodes: &[Bvh2Node], leaf_prims: &[LeafPrim], i: usize, seen: &mut [u32], depth: u32) -> Box3 {
        let Some(node) = nodes.get(i) else {
            c.err(format!("node index {i} out of range ({})", nodes.len()));
            return EMPTY;
        };
        seen[i] += 1;
        if seen[i] > 1 || depth > 64 {
            return EMPTY;
        }
        let mut total = EMPTY;
        for (side, index, count, lo, hi) in [
            ("left", node.left, node.left_count, node.left_min, node.left_max),
            ("right", node.right, node.right_count, node.right_min, node.right_max),
        ] {
            let at = format!("node {i} {side}");
            let exact = if count == 0 {
                visit(c, nodes, leaf_prims, index as usize, seen, depth + 1)
            } else {
                let mut b = EMPTY;
                let empty_box = lo[0] > hi[0];
                // A root over one primitive has a second child no ray reaches.
                if !(empty_box && nodes.len() == 1 && side == "right") {
                    if c.pieces.is_some() {
                        b = c.leaf_of_pieces(leaf_prims, index..index + count, (lo, hi), &at);
                    } else {
                        for k in 0..count {
                            b = union(b, c.leaf(leaf_prims, (index + k) as usize, &at));
                        }
                    }
                }
                b
            };
            if (0..3).any(|k| lo[k] > exact.0[k] || hi[k] < exact.1[k]) && exact.0[0] <= exact.1[0] {
                c.err(format!("{at}: box {lo:?}..{hi:?} does not contain {:?}..{:?}", exact.0, exact.1));
            }
            total = union(total, exact);
        }
        total
    }
    visit(&mut c, nodes, leaf_prims, 0, &mut seen_node, 0);
    for (i, &s) in seen_node.iter().enumerate() {
        if s != 1 {
            c.err(format!("node {i} reached {s} times"));
        }
    }
    c.finish()
}

/// Checks a 4-wide BVH of full-precision boxes (root 0) over `prims`; see
/// the module doc. Its node array also holds nodes no walk reaches (the
/// two-box layout's odd levels, `treelet_core::layouts::bvh4`): every node
/// is reached at most once, and every primitive exactly once.
pub fn validate_bvh4(prims: Primitives, nodes: &[Bvh4Node], leaf_prims: &[LeafPrim]) -> Validation {
    validate_bvh4_tree(prims, nodes, leaf_prims, false)
}

/// [`validate_bvh4`] for a tree over pieces of triangles (see
/// [`validate_bvh2_split`]).
pub fn validate_bvh4_split(prims: Primitives, nodes: &[Bvh4Node], leaf_prims: &[LeafPrim]) -> Validation {
    validate_bvh4_tree(prims, nodes, leaf_prims, true)
}

fn validate_bvh4_tree(prims: Primitives, nodes: &[Bvh4Node], leaf_prims: &[LeafPrim], split: bool) -> Validation {
    let mut c = Check::new(prims, split);
    if nodes.is_empty() {
        c.err("no nodes".into());
        return c.finish();
    }
    let mut seen_node = vec![0u32; nodes.len()];
    fn visit(c: &mut Check, nodes: &[Bvh4Node], leaf_prims: &[LeafPrim], i: usize, seen: &mut [u32], depth: u32) -> Box3 {
        let Some(node) = nodes.get(i) else {
            c.err(format!("node index {i} out of range ({})", nodes.len()));
            return EMPTY;
        };
        seen[i] += 1;
        if seen[i] > 1 {
            c.err(format!("node {i} reached twice"));
            return EMPTY;
        }
        if depth > 64 {
            c.err(format!("node {i} is deeper than 64 levels"));
            return EMPTY;
        }
        let mut total = EMPTY;
        for k in 0..4 {
            let (lo, hi) = ([node.lo_x[k], node.lo_y[k], node.lo_z[k]], [node.hi_x[k], node.hi_y[k], node.hi_z[k]]);
            let (index, count) = (node.child[k], node.count[k]);
            let at = format!("node {i} slot {k}");
            // A slot no ray reaches: an empty box on every axis.
            if (0..3).any(|a| lo[a] > hi[a]) {
                if !(0..3).all(|a| lo[a] > hi[a]) || count == 0 {
                    c.err(format!("{at}: box {lo:?}..{hi:?} is empty on some axes only, or names an internal node"));
                }
                continue;
            }
            let exact = if count == 0 {
                visit(c, nodes, leaf_prims, index as usize, seen, depth + 1)
            } else if c.pieces.is_some() {
                c.leaf_of_pieces(leaf_prims, index..index + count, (lo, hi), &at)
            } else {
                let mut b = EMPTY;
                for j in 0..count {
                    b = union(b, c.leaf(leaf_prims, (index + j) as usize, &at));
                }
                b
            };
            if (0..3).any(|a| lo[a] > exact.0[a] || hi[a] < exact.1[a]) && exact.0[0] <= exact.1[0] {
                c.err(format!("{at}: box {lo:?}..{hi:?} does not contain {:?}..{:?}", exact.0, exact.1));
            }
            total = union(total, exact);
        }
        total
    }
    visit(&mut c, nodes, leaf_prims, 0, &mut seen_node, 0);
    c.finish()
}
