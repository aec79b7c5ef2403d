//! Splitting large triangles before the build: T. Karras and T. Aila, "Fast
//! Parallel Construction of High-Quality Bounding Volume Hierarchies", HPG
//! 2013, section 5.1 ("triangle splitting"), after E. Ernst and G. Greiner,
//! "Early Split Clipping for Bounding Volume Hierarchies", 2007.
//!
//! A large or long triangle's box is mostly empty space, and every ray
//! through that space visits the triangle's leaf. Real scenes (a floor, a
//! wall, a cable across a street) have many; scans have none. So before the
//! Morton codes, each triangle may become several *references*: pieces of
//! it, each with the box of the part of the triangle inside it. The tree is
//! built over the references, and each leaf slot names its triangle, so a
//! triangle may sit in several leaves (a closest hit is the same hit from
//! any of them).
//!
//! Four kernels, one invocation per primitive unless said:
//! 1. [`priority_phase`]: each triangle's priority, how much of its box is
//!    wasted space ([`priority`]), and their sum per workgroup (the host
//!    adds those and sets [`SplitParams::scale`] so that the pieces over all
//!    triangles stay within the budget).
//! 2. [`count_kernel`]: pieces per primitive, `1 + ⌊priority · scale⌋`, at
//!    most [`MAX_PIECES`]; the host scans the counts into offsets.
//! 3. [`emit_kernel`]: each primitive writes its pieces' boxes and its own
//!    index at its offset ([`split_triangle`]).
//! 4. [`StoredBoxes`], through [`crate::construct::bounds`]: the pieces'
//!    boxes as the build's boxes, with their centroid bounds.
//!
//! After the hierarchy, [`remap_kernel`] turns each leaf slot's reference
//! into its primitive, so that every later stage (treelets, collapse,
//! layouts, traversal) sees primitive indices as without splits.
//!
//! Where Treelet departs from the paper: the priority is the cube root of
//! the box's wasted half area times its longest side (as madmann91/bvh's
//! `heuristic_primitive_splitter` and IDKEngine do: the paper's `X^i`
//! weight of the plane's level is left out); the paper's planes, those of
//! the Morton grid, are kept: each split cuts at the grid's highest-level
//! plane through the piece ([`split_plane`]), so pieces fall on the cells
//! the LBVH's top levels separate. A piece's box is the box of the part of
//! the whole triangle on its side of the plane, cut to its parent's box:
//! conservative (never smaller than the exact piece), so the pieces cover
//! the triangle; crossing points are widened by a few ulps for rounding.
use glam::Vec3;

use crate::construct::bounds::BoxSource;
use crate::construct::morton::MortonFrame;
use crate::construct::primitive_boxes::primitive_box;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{SplitParams, Sphere};
use crate::geometry::records::RecordStore;
use crate::geometry::split::Split;
use crate::geometry::triangle::Triangle;
use crate::gpu::unchecked::{get, set};
use crate::gpu::workgroup::{WG, WG_LOG2, WORKGROUP_SIZE, reduction_stride};

/// Most pieces one primitive becomes.
pub const MAX_PIECES: u32 = 64;
/// Pieces waiting on [`split_triangle`]'s stack: it goes on with the half
/// of fewer pieces, so at most `log2(MAX_PIECES)` wait.
const STACK: usize = 7;
const _: () = assert!(1 << (STACK - 1) >= MAX_PIECES);

/// Priorities each invocation of [`priority_phase`] computes.
pub const PRIORITY_ITEMS: u32 = 8;
/// Priorities per workgroup (one partial sum each).
pub const PRIORITY_TILE: u32 = WORKGROUP_SIZE * PRIORITY_ITEMS;
/// Phases of [`priority_phase`]: priorities, tree reduction, write.
pub const PRIORITY_PHASES: u32 = 2 + WG_LOG2;

/// Cells of the Morton grid per axis (`crate::construct::morton`'s 21 bits).
const GRID: u32 = 1 << 21;

/// How much splitting `t` would gain: the cube root of its box's longest
/// side times its wasted half area, the box's half area less the least
/// that boxes of ever smaller pieces tend to (the triangle's area projected
/// on the three planes, `(|nx| + |ny| + |nz|) / 2` of the unnormalized
/// normal). 0 for flat shapes that are not triangles, degenerate
/// triangles, boxes too large for `f32` areas, and triangles longer than
/// `reach` ([`reach`]: twice the spread of all centroids, as a ground
/// around a building is): an optimizer lifts such a triangle whole to the
/// root, where every ray tests it once, while its pieces would fall into the
/// Morton cells of the detail they lie under, out of the treelets' reach
/// (the classroom of `docs/results/h200-real-scenes-2026-11-29/`).
#[inline]
pub fn priority(t: &Triangle, reach: f32) -> f32 {
    if !t.is_triangle() {
        return 0.0;
    }
    let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
    let d = a.max(b).max(c) - a.min(b).min(c);
    let longest = d.x.max(d.y).max(d.z);
    let half_area = d.x * d.y + d.y * d.z + d.z * d.x;
    let n = (b - a).cross(c - a);
    let ideal = 0.5 * (n.x.abs() + n.y.abs() + n.z.abs());
    let p = libm::cbrtf(longest * (half_area - ideal).max(0.0));
    if p.is_finite() && longest <= reach { p } else { 0.0 }
}

/// The longest triangle that [`priority`] lets be split: twice the largest
/// side of the primitives' centroid bounds, from the Morton frame (its
/// scale is `2^21` cells over half that side); no limit where all
/// centroids are one point.
#[inline]
pub fn reach(frame: &MortonFrame) -> f32 {
    let scale = frame.scale.max_element();
    if scale > 0.0 { 4.0 * (GRID as f32) / scale } else { f32::MAX }
}

/// Kernel: the priority of each of the `n` primitives (spheres first, 0)
/// into `priorities`, and each workgroup's sum into `partials[group]`,
/// over [`PRIORITY_TILE`] primitives a workgroup, summed in a fixed order.
#[allow(clippy::too_many_arguments)]
pub fn priority_phase(
    phase: u32,
    lid: u32,
    group: u32,
    params: &SplitParams,
    triangles: Split<Triangle>,
    priorities: &mut [f32],
    partials: &mut [f32],
    shared: &mut [f32; WG],
) {
    if phase == 0 {
        let mut sum = 0.0;
        for k in 0..PRIORITY_ITEMS {
            let i = group * PRIORITY_TILE + k * WORKGROUP_SIZE + lid;
            if i < params.n {
                let p = if i < params.spheres { 0.0 } else { priority(&triangles.get((i - params.spheres) as usize), params.reach) };
                priorities[i as usize] = p;
                sum += p;
            }
        }
        set(shared, lid as usize, sum);
    } else if phase <= WG_LOG2 {
        let stride = reduction_stride(phase - 1);
        if lid < stride {
            set(shared, lid as usize, get(shared, lid as usize) + get(shared, (lid + stride) as usize));
        }
    } else if lid == 0 && group * PRIORITY_TILE < params.n {
        partials[group as usize] = get(shared, 0);
    }
}

/// Kernel, `n + 1` invocations: `counts[id]`, the pieces primitive `id`
/// becomes, `1 + ⌊priority · scale⌋` and at most [`MAX_PIECES`]
/// (NaN and negative products give none extra); `counts[n] = 0`, so that
/// the scanned counts end with the total.
#[inline]
pub fn count_kernel(id: u32, params: &SplitParams, priorities: &[f32], counts: &mut [u32]) {
    if id < params.n {
        counts[id as usize] = pieces(priorities[id as usize], params.scale);
    } else if id == params.n {
        counts[id as usize] = 0;
    }
}

/// `1 + ⌊p · scale⌋`, at most [`MAX_PIECES`].
#[inline]
pub fn pieces(p: f32, scale: f32) -> u32 {
    let extra = p * scale;
    if extra >= 1.0 {
        1 + (extra.min((MAX_PIECES - 1) as f32) as u32)
    } else {
        1
    }
}

/// Kernel: primitive `id`'s pieces, `offsets[id]..offsets[id + 1]` (the
/// scanned counts): their boxes into `ref_boxes` and `id` into `ref_prims`.
#[allow(clippy::too_many_arguments)]
pub fn emit_kernel<B: RecordStore<Aabb> + ?Sized>(
    id: u32,
    params: &SplitParams,
    sphere_data: &[Sphere],
    triangles: Split<Triangle>,
    offsets: &[u32],
    ref_boxes: &mut B,
    ref_prims: &mut [u32],
) {
    if id >= params.n {
        return;
    }
    let start = offsets[id as usize];
    let count = offsets[id as usize + 1] - start;
    let whole = primitive_box(id, params.spheres, sphere_data, &triangles);
    if count <= 1 || id < params.spheres {
        ref_boxes.store(start as usize, &whole);
        ref_prims[start as usize] = id;
        return;
    }
    let frame = MortonFrame { offset: Vec3::from_array(params.frame.min), scale: Vec3::from_array(params.frame.max) };
    let tri = triangles.get((id - params.spheres) as usize);
    split_triangle(&tri, whole, count, &frame, ref_boxes, ref_prims, start, id);
}

/// Splits triangle `id`, `t` (box `whole`), into `count` pieces, written
/// from `start` on: each piece's box into `boxes`, `id` into `prims`. A
/// piece is halved at [`split_plane`], its pieces shared between the
/// halves by their longest sides. A piece that a plane does not divide
/// (rounding on a sliver) is written as often as pieces were meant for it:
/// a duplicate costs a slot, never a miss. (The outputs are arguments, not
/// a closure's captures: a shader cannot keep pointers to its buffers in
/// a closure's state.)
#[allow(clippy::too_many_arguments)]
pub fn split_triangle<B: RecordStore<Aabb> + ?Sized>(
    t: &Triangle,
    whole: Aabb,
    count: u32,
    frame: &MortonFrame,
    boxes_out: &mut B,
    prims_out: &mut [u32],
    start: u32,
    id: u32,
) {
    let mut out = start;
    let (a, b, c) = (Vec3::from_array(t.v0), Vec3::from_array(t.v1), Vec3::from_array(t.v2));
    // Stored pieces are widened on every axis by 2^-20 of the triangle's
    // largest coordinate: the watertight test may report a hit a rounding
    // off the triangle's plane (a grazing ray beside a large floor), which
    // its whole box holds only where it is thick; a flat piece must too.
    let widen = Vec3::splat(whole.lo().abs().max(whole.hi().abs()).max_element() * (1.0 / 1_048_576.0));
    let mut boxes = [Aabb::EMPTY; STACK];
    let mut counts = [0u32; STACK];
    let mut top = 0usize;
    let mut piece = whole;
    let mut left_to_emit = count;
    loop {
        let mut done = left_to_emit <= 1;
        if !done {
            let (axis, pos) = split_plane(&piece, frame);
            let below = intersection(&half_box(a, b, c, axis, pos, true), &piece);
            let above = intersection(&half_box(a, b, c, axis, pos, false), &piece);
            if axis > 2 || below.is_empty() || above.is_empty() {
                // Not divided: every piece meant for it is this one.
                while left_to_emit > 1 {
                    boxes_out.store(out as usize, &Aabb::new(piece.lo() - widen, piece.hi() + widen));
                    prims_out[out as usize] = id;
                    out += 1;
                    left_to_emit -= 1;
                }
                done = true;
            } else {
                let (lb, la) = (below.extent().max_element(), above.extent().max_element());
                let share = libm::roundf(left_to_emit as f32 * lb / (lb + la)) as u32;
                let n_below = share.clamp(1, left_to_emit - 1);
                let n_above = left_to_emit - n_below;
                // Go on with the half of fewer pieces, keep the other.
                let (go, go_n, keep, keep_n) =
                    if n_below <= n_above { (below, n_below, above, n_above) } else { (above, n_above, below, n_below) };
                set(&mut boxes, top, keep);
                set(&mut counts, top, keep_n);
                top += 1;
                piece = go;
                left_to_emit = go_n;
            }
        }
        if done {
            boxes_out.store(out as usize, &Aabb::new(piece.lo() - widen, piece.hi() + widen));
            prims_out[out as usize] = id;
            out += 1;
            if top == 0 {
                return;
            }
            top -= 1;
            piece = get(&boxes, top);
            left_to_emit = get(&counts, top);
        }
    }
}

/// Component `axis` of `v`.
#[inline]
fn component(v: Vec3, axis: u32) -> f32 {
    if axis == 0 {
        v.x
    } else if axis == 1 {
        v.y
    } else {
        v.z
    }
}

/// The plane that halves `piece`: of the Morton grid's planes (those of
/// `frame`, cubic cells of 2^21 a side) strictly inside the piece, the one
/// of the highest level (the coarsest grid it belongs to; the longer side
/// on a tie), else the middle of the longest side. Returns `(axis,
/// position)`; axis 3 where even the middle is not inside (a point).
pub fn split_plane(piece: &Aabb, frame: &MortonFrame) -> (u32, f32) {
    let (lo, hi) = (piece.lo(), piece.hi());
    let extent = piece.extent();
    let mut best_axis = 3u32;
    let mut best_level = 0u32;
    let mut best_pos = 0.0f32;
    let mut best_extent = 0.0f32;
    for axis in 0..3u32 {
        let scale = component(frame.scale, axis);
        if scale <= 0.0 {
            continue;
        }
        let offset = component(frame.offset, axis);
        // Cell coordinates, clamped before the integer conversion.
        let cell = |x: f32| ((x * 0.5 - offset) * scale).clamp(-1.0, GRID as f32 + 1.0);
        let first = libm::floorf(cell(component(lo, axis))) + 1.0;
        let last = libm::ceilf(cell(component(hi, axis))) - 1.0;
        let (first, last) = (first.max(1.0), last.min(GRID as f32));
        if first > last {
            continue;
        }
        let (first, last) = (first as u32, last as u32);
        // The multiple of the highest power of two in first..=last: the
        // highest bit where first - 1 and last differ.
        let level = 31 - ((first - 1) ^ last).leading_zeros();
        let k = last & !((1u32 << level) - 1);
        let pos = (k as f32 / scale + offset) * 2.0;
        let e = component(extent, axis);
        if pos > component(lo, axis)
            && pos < component(hi, axis)
            && (best_axis > 2 || level > best_level || (level == best_level && e > best_extent))
        {
            (best_axis, best_level, best_pos, best_extent) = (axis, level, pos, e);
        }
    }
    if best_axis <= 2 {
        return (best_axis, best_pos);
    }
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let pos = component(lo, axis) * 0.5 + component(hi, axis) * 0.5;
    if pos > component(lo, axis) && pos < component(hi, axis) { (axis, pos) } else { (3, 0.0) }
}

/// The box of the part of triangle `a b c` at or below (`below`) or at or
/// above the plane `axis = pos`: its vertices on that side and the points
/// where its edges cross the plane, those widened on the other two axes
/// by 2^-20 of the edge's largest coordinate (the interpolation's
/// rounding is a few ulps); empty where no part is on that side.
#[inline]
pub fn half_box(a: Vec3, b: Vec3, c: Vec3, axis: u32, pos: f32, below: bool) -> Aabb {
    let mut out = Aabb::EMPTY;
    out = edge_part(out, a, b, axis, pos, below);
    out = edge_part(out, b, c, axis, pos, below);
    edge_part(out, c, a, axis, pos, below)
}

/// `out` grown by `p` if it is on the side, and by where `p q` crosses the plane.
#[inline]
fn edge_part(out: Aabb, p: Vec3, q: Vec3, axis: u32, pos: f32, below: bool) -> Aabb {
    let (dp, dq) = (component(p, axis) - pos, component(q, axis) - pos);
    let mut out = out;
    if (below && dp <= 0.0) || (!below && dp >= 0.0) {
        out = out.grow(p);
    }
    if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
        let t = dp / (dp - dq);
        let x = p + (q - p) * t;
        let mask = Vec3::new(
            if axis == 0 { 0.0 } else { 1.0 },
            if axis == 1 { 0.0 } else { 1.0 },
            if axis == 2 { 0.0 } else { 1.0 },
        );
        let pad = p.abs().max(q.abs()) * (1.0 / 1_048_576.0) * mask;
        // On the plane exactly.
        let x = x * mask + Vec3::splat(pos) * (Vec3::ONE - mask);
        out = out.grow(x - pad).grow(x + pad);
    }
    out
}

/// The common part of two boxes (empty where they do not meet).
#[inline]
pub fn intersection(a: &Aabb, b: &Aabb) -> Aabb {
    Aabb::new(a.lo().max(b.lo()), a.hi().min(b.hi()))
}

/// Kernel: primitive slot `j` of the built tree (of `n`) names its
/// reference's primitive: `values[j] = ref_prims[values[j]]`.
#[inline]
pub fn remap_kernel(j: u32, n: u32, ref_prims: &[u32], values: &mut [u32]) {
    if j < n {
        values[j as usize] = ref_prims[values[j as usize] as usize];
    }
}

/// The pieces' boxes as [`crate::construct::bounds::primitive_bounds_phase`]
/// reads them, to write them as the build's boxes with their centroid bounds.
pub struct StoredBoxes<'a> {
    pub boxes: &'a [Aabb],
}

impl BoxSource for StoredBoxes<'_> {
    #[inline]
    fn box_of(&mut self, i: u32) -> Aabb {
        crate::gpu::unchecked::at(self.boxes, i as usize)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle::new(a, b, c)
    }

    /// The `count` pieces' boxes, after checking each slot was written once with triangle 7.
    fn pieces_of(t: &Triangle, whole: Aabb, count: u32, frame: &MortonFrame) -> Vec<Aabb> {
        let mut boxes = std::vec![Aabb::from_arrays([f32::NAN; 3], [f32::NAN; 3]); count as usize + 2];
        let mut prims = std::vec![u32::MAX; count as usize + 2];
        split_triangle(t, whole, count, frame, &mut boxes[..], &mut prims[..], 1, 7);
        assert!(prims[1..=count as usize].iter().all(|&p| p == 7) && prims[0] == u32::MAX && prims[count as usize + 1] == u32::MAX);
        boxes[1..=count as usize].to_vec()
    }

    /// Whether point `p` is in some box, give or take an ulp (`p` was rounded).
    fn covered(boxes: &[Aabb], p: Vec3) -> bool {
        let slack = p.abs() * 1.2e-7;
        boxes.iter().any(|b| (b.lo() - slack).cmple(p).all() && (b.hi() + slack).cmpge(p).all())
    }

    #[test]
    fn an_axis_aligned_square_half_wastes_nothing_and_a_diagonal_sliver_wastes_much() {
        let flat = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Box half area 1, projected area 0.5: wasted 0.5.
        assert!((priority(&flat, f32::MAX) - libm::cbrtf(0.5)).abs() < 1e-6);
        assert_eq!(priority(&flat, 0.5), 0.0);
        let sliver = tri([0.0, 0.0, 0.0], [100.0, 100.0, 100.0], [100.0, 100.0, 100.01]);
        assert!(priority(&sliver, f32::MAX) > 10.0 * priority(&flat, f32::MAX));
        let degenerate = tri([1.0; 3], [1.0; 3], [1.0; 3]);
        assert_eq!(priority(&degenerate, f32::MAX), 0.0);
        let huge = tri([-3e38, 0.0, 0.0], [3e38, 1.0, 0.0], [0.0, 3e38, 3e38]);
        assert_eq!(priority(&huge, f32::MAX), 0.0);
    }

    #[test]
    fn reach_is_twice_the_centroids_spread() {
        let frame = MortonFrame::new(&Aabb::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(7.0, 2.0, 1.0)));
        assert!((reach(&frame) - 20.0).abs() < 1e-4, "{}", reach(&frame));
        assert_eq!(reach(&MortonFrame::new(&Aabb::point(Vec3::ONE))), f32::MAX);
    }

    #[test]
    fn pieces_are_bounded_and_nan_gives_one() {
        assert_eq!(pieces(0.0, 10.0), 1);
        assert_eq!(pieces(0.25, 10.0), 3);
        assert_eq!(pieces(f32::NAN, 1.0), 1);
        assert_eq!(pieces(1e30, 1e30), MAX_PIECES);
    }

    #[test]
    fn the_plane_is_the_grids_highest_level_one_inside() {
        let frame = MortonFrame::new(&Aabb::new(Vec3::ZERO, Vec3::splat(16.0)));
        // x from 3 to 13 holds the grid's middle plane, x = 8.
        let (axis, pos) = split_plane(&Aabb::new(Vec3::new(3.0, 1.0, 1.0), Vec3::new(13.0, 2.0, 2.0)), &frame);
        assert_eq!((axis, pos), (0, 8.0));
        // y from 9 to 11.5 holds 10, 11 (and finer); 10 is a multiple of 2 levels up more.
        let (axis, pos) = split_plane(&Aabb::new(Vec3::new(1.0, 9.0, 1.0), Vec3::new(1.5, 11.5, 1.2)), &frame);
        assert_eq!((axis, pos), (1, 10.0));
    }

    #[test]
    fn pieces_cover_the_triangle_and_stay_inside_its_box() {
        let frame = MortonFrame::new(&Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)));
        let mut rng = 12345u64;
        let mut next = || {
            rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((rng >> 40) as f32 / (1u64 << 24) as f32) * 100.0 - 50.0
        };
        for _ in 0..200 {
            let t = tri([next(), next(), next()], [next(), next(), next()], [next(), next(), next()]);
            let whole = t.aabb();
            for count in [2, 3, 7, 64] {
                let boxes = pieces_of(&t, whole, count, &frame);
                let area: f64 = boxes.iter().map(|b| b.half_area_f64()).sum();
                let widen = Vec3::splat(whole.lo().abs().max(whole.hi().abs()).max_element() / 1_048_576.0);
                let widened = Aabb::new(whole.lo() - widen, whole.hi() + widen);
                assert!(boxes.iter().all(|b| widened.contains(b)));
                assert!(area <= whole.half_area_f64() * count as f64);
                // Points of the triangle in f64, each within rounding of a box.
                for i in 0..=20 {
                    for j in 0..=(20 - i) {
                        let (u, v, w) = (i as f64 / 20.0, j as f64 / 20.0, (20 - i - j) as f64 / 20.0);
                        let p = [0, 1, 2].map(|k| (t.v0[k] as f64 * w + t.v1[k] as f64 * u + t.v2[k] as f64 * v) as f32);
                        let p = Vec3::from_array(p);
                        assert!(covered(&boxes, p), "{p:?} of {t:?} outside its {count} pieces {boxes:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn splitting_a_long_sliver_shrinks_its_boxes() {
        let frame = MortonFrame::new(&Aabb::new(Vec3::ZERO, Vec3::splat(64.0)));
        let t = tri([0.0, 0.0, 0.0], [64.0, 64.0, 0.0], [64.0, 64.0, 0.1]);
        let boxes = pieces_of(&t, t.aabb(), 16, &frame);
        let area: f64 = boxes.iter().map(|b| b.half_area_f64()).sum();
        assert!(area < 0.2 * t.aabb().half_area_f64(), "{area} of {}", t.aabb().half_area_f64());
    }
}
