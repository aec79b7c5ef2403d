//! Ray/sphere and ray/box intersection in f32, robust enough for smallpt's
//! 1e5-radius walls.
//!
//! Ray/sphere follows Haines, Günther & Akenine-Möller, "Precision
//! Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7): the
//! discriminant as `r² - |f - (f·d)d|²` and the near root as `c / q`, which
//! avoids the cancellation of `-b ± sqrt(disc)`. Treelet goes one step
//! further: `c = |f|² - r²` and the discriminant are differences of nearly
//! equal squares for a huge sphere seen from near its surface, so both are
//! summed with error-free transformations (two-product by fused multiply-add,
//! two-sum), which keeps the hit distance to a few ulps there too.
use glam::Vec3;

use crate::geometry::buffers::Node;

/// No hit.
pub const MISS: f32 = f32::MAX;

/// `a * b` as an unevaluated sum `p + e`, exactly: by a fused multiply-add
/// on the GPU; elsewhere by Dekker's product, whose operands are split into
/// 12-bit halves (Veltkamp) so that every partial product is exact. Baseline
/// x86-64 has no FMA instruction, and `libm::fmaf` there is a call through
/// a pointer: eight of them a sphere test, which spilled its registers
/// around each (`ray_sphere_mode` was 57% of the CPU runner's time on
/// cornell). Both give the same two floats, so the CPU runner still
/// matches the GPU bit for bit (short of products under 1e-30, where the
/// low part's own rounding may differ, far below any distance we compare).
#[inline]
fn two_prod(a: f32, b: f32) -> (f32, f32) {
    let p = a * b;
    #[cfg(target_arch = "spirv")]
    {
        (p, libm::fmaf(a, b, -p))
    }
    #[cfg(not(target_arch = "spirv"))]
    {
        let ((ah, al), (bh, bl)) = (veltkamp_split(a), veltkamp_split(b));
        (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
    }
}

/// `a` as `hi + lo`, each with at most 12 significant bits (exact for
/// `|a|` below 8e34: `4097 * a` must not overflow, and squares past 1.8e19
/// overflow `two_prod` first).
#[cfg(not(target_arch = "spirv"))]
#[inline]
fn veltkamp_split(a: f32) -> (f32, f32) {
    let c = 4097.0 * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

/// `a + b` as an unevaluated sum `s + e`, exactly.
#[inline]
fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `|v|² - r²`, compensated: accurate even when the two nearly cancel.
#[inline]
pub fn length_sq_minus_sq(v: Vec3, r: f32) -> f32 {
    let (xx, ex) = two_prod(v.x, v.x);
    let (yy, ey) = two_prod(v.y, v.y);
    let (zz, ez) = two_prod(v.z, v.z);
    let (rr, er) = two_prod(r, r);
    let (s1, e1) = two_sum(xx, yy);
    let (s2, e2) = two_sum(s1, zz);
    let (s3, e3) = two_sum(s2, -rr);
    s3 + (((ex + ey) + (ez - er)) + ((e1 + e2) + e3))
}

/// Distance along the unit direction `d` from `o` to the first hit with the
/// sphere (`center`, `radius`) beyond `t_min`, or [`MISS`].
///
/// ```
/// use glam::Vec3;
/// use treelet_core::geometry::intersect::{ray_sphere, MISS};
/// let t = ray_sphere(Vec3::ZERO, Vec3::X, Vec3::new(10.0, 0.0, 0.0), 2.0, 0.0);
/// assert_eq!(t, 8.0);
/// assert_eq!(ray_sphere(Vec3::ZERO, -Vec3::X, Vec3::new(10.0, 0.0, 0.0), 2.0, 0.0), MISS);
/// ```
#[inline]
pub fn ray_sphere(o: Vec3, d: Vec3, center: Vec3, radius: f32, t_min: f32) -> f32 {
    ray_sphere_mode(o, d, center, radius, t_min, false)
}

/// As [`ray_sphere`], but with `far_only` only the far root counts: for a
/// ray that leaves a sphere's surface into the sphere, whose near root is
/// the surface it starts on. (Near a sphere of radius 1e5 centred 1e5 from
/// the origin, f32 cannot place a point closer to the surface than about
/// 0.004, so no offset makes that near root reliably negative.)
#[inline]
pub fn ray_sphere_mode(o: Vec3, d: Vec3, center: Vec3, radius: f32, t_min: f32, far_only: bool) -> f32 {
    let f = o - center;
    let b = f.dot(d); // half of the usual b, as |d| = 1
    let c = length_sq_minus_sq(f, radius);
    let l = f - b * d; // from the centre to the closest point of the line
    let disc = -length_sq_minus_sq(l, radius);
    if disc < 0.0 {
        return MISS;
    }
    let root = libm::sqrtf(disc);
    let q = -(b + if b >= 0.0 { root } else { -root });
    if q == 0.0 {
        return MISS;
    }
    let (t0, t1) = (c / q, q);
    let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    if far_only {
        return if far > t_min { far } else { MISS };
    }
    if near > t_min {
        near
    } else if far > t_min {
        far
    } else {
        MISS
    }
}

/// Reciprocal of a direction; components that are zero (or too small to
/// invert) become 0 and mark that axis as parallel for [`ray_box`].
#[inline]
pub fn safe_inverse(d: Vec3) -> Vec3 {
    let inv = |x: f32| if x.abs() < 1e-30 { 0.0 } else { 1.0 / x };
    Vec3::new(inv(d.x), inv(d.y), inv(d.z))
}

/// A ray as the branch-free slab tests of the traversal layouts
/// ([`crate::trace::bvh2`], [`crate::trace::cwbvh`]) take it: origin, reciprocal
/// direction, and a bias for far distances.
///
/// An axis the ray runs parallel to (or too nearly to invert) gets
/// `±f32::MAX`, with the direction's sign, for an inverse instead of an
/// infinity, so `(plane - origin) * inverse` is never NaN (never `0 * inf`)
/// and its sign is exact. That alone would make a ray lying exactly in a
/// box's far face leave the slab at `t = 0`, so far distances on such an
/// axis get a bias `b` added: the ray stays in the slab for every
/// `t <= b`, and a box that lies `e` beside it passes the test on that
/// axis when `e < b / f32::MAX`. [`SlabRay::new`] sets `b = f32::MAX`,
/// right for every box but a window of one unit: an axis-parallel ray
/// (an engine's ray straight down, a diffuse bounce along an axis-aligned
/// wall's normal) then entered every box within a unit of it, 15 630
/// nodes and leaf primitives against a median of 21 for a diffuse ray
/// inside the staircase scene. [`SlabRay::within`] lowers `b` to twice the
/// distance at which the ray leaves the tree's root box, past which no box
/// of the tree can be met: the window shrinks to that distance over
/// `f32::MAX` (under `1e-36` for a scene of a hundred units). Near
/// distances need nothing: a ray in a near face enters at 0.
#[derive(Clone, Copy)]
pub struct SlabRay {
    pub o: [f32; 3],
    pub inv: [f32; 3],
    pub far_bias: [f32; 3],
}

impl SlabRay {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let d = d.to_array();
        let mut inv = [0.0f32; 3];
        let mut far_bias = [0.0f32; 3];
        for k in 0..3 {
            let r = 1.0 / d[k];
            if r.abs() <= f32::MAX {
                inv[k] = r;
            } else {
                inv[k] = f32::from_bits((d[k].to_bits() & 0x8000_0000) | f32::MAX.to_bits());
                far_bias[k] = f32::MAX;
            }
        }
        SlabRay { o: o.to_array(), inv, far_bias }
    }

    /// Whether the ray runs parallel to an axis (see the type's doc).
    #[inline]
    pub fn is_parallel(&self) -> bool {
        self.far_bias[0] != 0.0 || self.far_bias[1] != 0.0 || self.far_bias[2] != 0.0
    }

    /// The ray with the far bias of its parallel axes cut down to twice the
    /// distance at which it leaves the box `lo..hi` (the root's: every box
    /// it will be tested against lies inside), so that it no longer enters
    /// boxes up to a unit beside it (see the type's doc). A ray with no
    /// parallel axis is returned as it is.
    ///
    /// Why twice is enough: a box inside the root that the ray meets is
    /// entered, by the other axes' near distances, no later than the ray
    /// leaves the root, and those distances are computed within a few ulps;
    /// the bias only has to stay above them.
    #[inline]
    pub fn within(self, lo: [f32; 3], hi: [f32; 3]) -> SlabRay {
        if !self.is_parallel() {
            return self;
        }
        let mut exit = f32::MAX;
        for k in 0..3 {
            if self.far_bias[k] == 0.0 {
                let far = if self.inv[k] >= 0.0 { hi[k] } else { lo[k] };
                exit = exit.min((far - self.o[k]) * self.inv[k]);
            }
        }
        // Past f32::MAX / 2 the bias stays f32::MAX; a ray that leaves the
        // root behind its origin meets nothing past 0 and gets 0.
        let bias = if exit <= f32::MAX / 2.0 { (2.0 * exit).max(0.0) } else { f32::MAX };
        let mut ray = self;
        for k in 0..3 {
            if ray.far_bias[k] != 0.0 {
                ray.far_bias[k] = bias;
            }
        }
        ray
    }
}

/// How much a slab test widens its far distance: `1 + 2^-21`, above the
/// `1 + 2γ(3)` (`1 + 3.6e-7`, about `1 + 2^-21.4`) that Ize ("Robust BVH Ray Traversal",
/// 2013) needs for three roundings of `(plane - o) * inv`, so that no box
/// the ray touches is culled. Kept that small because it widens every box
/// sideways by the distance times itself: at `2^-14` (779c44d, one
/// constant for this and [`TIE_WIDENING`]) primary rays through a grid of
/// 1 024 scanned bunnies, a hundred bunnies away, entered leaves they
/// missed by that much and lost a third of their speed on the H200
/// (docs/results/h200-instances-fix-2026-12-03). Ties need none of it:
/// `tests/layouts.rs` passes with it and fails without [`TIE_WIDENING`].
pub const FAR_WIDENING: f32 = 1.0 + 1.0 / 2_097_152.0;

/// How much a traversal widens the closest hit's distance before it culls
/// boxes by it ([`crate::trace::hit::Hit::reach`]): `1 + 2^-14`, for ties.
/// A ray through a vertex or edge that several primitives share hits them
/// all at one distance, and the lowest index must win, as in the scan
/// ([`crate::trace::hit::Hit::is_beaten_by`]); the winner's box is entered
/// exactly at that distance, but the slab test computes the entry apart
/// from the primitive test's distance, and it may round a few ulps above
/// it. (Rays along an axis through a mesh's vertices lost such ties in
/// every layout.) It only lets in boxes that start just behind the hit,
/// so it may be generous.
///
/// (Folding this and [`FAR_WIDENING`] into one multiply of the clipped far
/// distance, as `ray_box` does, made the `bvh2` walk 1-3% slower on the
/// H200 than a multiply a node: docs/results/h200-axis-rays-2026-12-02.)
pub const TIE_WIDENING: f32 = 1.0 + 1.0 / 16384.0;

/// The interval `[near, far]` over which the ray is inside the box
/// `lo..hi` (far widened by [`FAR_WIDENING`]), clipped to `0..=t_max`; the
/// ray meets the box where `near <= far`. Traversals pass the closest hit's
/// [`reach`](crate::trace::hit::Hit::reach) for `t_max`.
#[inline]
pub fn slab_interval(lo: [f32; 3], hi: [f32; 3], ray: &SlabRay, t_max: f32) -> (f32, f32) {
    let t = |k: usize| {
        let (near, far) = if ray.inv[k] >= 0.0 { (lo[k], hi[k]) } else { (hi[k], lo[k]) };
        ((near - ray.o[k]) * ray.inv[k], (far - ray.o[k]) * ray.inv[k] + ray.far_bias[k])
    };
    let ((nx, fx), (ny, fy), (nz, fz)) = (t(0), t(1), t(2));
    let near = nx.max(ny).max(nz.max(0.0));
    let far = (fx.min(fy).min(fz) * FAR_WIDENING).min(t_max);
    (near, far)
}

/// Slab test of a node's box against a ray, hits between 0 and `t_max`.
/// An axis the ray runs parallel to (zero in `inv_d`) admits every `t` when
/// the origin lies within the slab, boundaries included, and none otherwise.
/// The far distance is widened by [`FAR_WIDENING`], `t_max` by
/// [`TIE_WIDENING`].
#[inline]
pub fn ray_box(node: &Node, o: Vec3, inv_d: Vec3, t_max: f32) -> bool {
    // Arrays, not `Vec3` indexing (which rust-gpu lowers to pointer phis).
    let (lo, hi, o, inv_d) = (node.min, node.max, o.to_array(), inv_d.to_array());
    let mut near = 0.0f32;
    let mut far = t_max * TIE_WIDENING;
    for k in 0..3 {
        if inv_d[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return false;
            }
        } else {
            let t1 = (lo[k] - o[k]) * inv_d[k];
            let t2 = (hi[k] - o[k]) * inv_d[k];
            near = near.max(t1.min(t2));
            far = far.min(t1.max(t2) * FAR_WIDENING);
        }
    }
    near <= far
}

/// Distance to push a ray off a surface at `p`: 2^-18 of its largest
/// coordinate (about 32 ulps), so the new ray cannot hit the surface again
/// through rounding, at any scale.
#[inline]
pub fn surface_offset(p: Vec3) -> f32 {
    p.abs().max_element().max(1e-30) * (1.0 / 262_144.0)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Dekker's product is exact: `p + e` is the f64 product of the two
    /// floats (48 significant bits, exact in f64), over magnitudes from
    /// 1e-15 to 1e15, signs and cancellations included.
    #[test]
    fn two_prod_is_exact() {
        let mut state = 0x2545_f491u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        };
        for _ in 0..200_000 {
            let mut float = || {
                let m = (next() >> 8) as f32 / 16_777_216.0 + 0.5;
                let e = (next() % 101) as i32 - 50;
                let s = if next() & 1 == 0 { 1.0 } else { -1.0 };
                s * m * libm::powf(2.0, e as f32)
            };
            let (a, b) = (float(), float());
            let (p, e) = two_prod(a, b);
            assert_eq!(p as f64 + e as f64, a as f64 * b as f64, "{a:e} * {b:e}");
            assert_eq!((p, e), (a * b, libm::fmaf(a, b, -(a * b))), "{a:e} * {b:e}: not the FMA's pair");
        }
    }

    /// Reference: the same query in f64 with the same stable formulas.
    fn ray_sphere_f64(o: [f64; 3], d: [f64; 3], c: [f64; 3], r: f64) -> Option<f64> {
        let f = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let b = (f[0] * d[0] + f[1] * d[1] + f[2] * d[2]) / dd;
        let l = [f[0] - b * d[0], f[1] - b * d[1], f[2] - b * d[2]];
        let disc = r * r - (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        if disc < 0.0 {
            return None;
        }
        let cc = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - r * r;
        let q = -(b + disc.sqrt().copysign(b));
        let (t0, t1) = (cc / q, q);
        let (near, far) = (t0.min(t1), t0.max(t1));
        let s = dd.sqrt();
        if near > 0.0 {
            Some(near * s)
        } else if far > 0.0 {
            Some(far * s)
        } else {
            None
        }
    }

    /// Worst relative error of the f32 hit distance over a set of rays.
    /// (origin, direction, centre, radius)
    type Case = ([f32; 3], [f32; 3], [f32; 3], f32);

    fn worst_error(cases: &[Case]) -> f64 {
        let mut worst = 0.0f64;
        for &(o, d, c, r) in cases {
            let dn = Vec3::from_array(d).normalize();
            let t = ray_sphere(Vec3::from_array(o), dn, Vec3::from_array(c), r, 0.0);
            let reference = ray_sphere_f64(o.map(f64::from), dn.to_array().map(f64::from), c.map(f64::from), r as f64);
            match reference {
                Some(tr) => {
                    assert!(t != MISS, "missed: o {o:?} d {d:?} c {c:?} r {r}, f64 hit at {tr}");
                    worst = worst.max(((t as f64) - tr).abs() / tr);
                }
                None => assert_eq!(t, MISS, "false hit: o {o:?} d {d:?} c {c:?} r {r}"),
            }
        }
        worst
    }

    fn directions() -> Vec<[f32; 3]> {
        let mut v = Vec::new();
        for i in 0..40 {
            let a = i as f32 * 0.157;
            v.push([libm::cosf(a) * 0.3, libm::sinf(a) * 0.3, -1.0]);
        }
        v
    }

    #[test]
    fn huge_spheres_seen_from_100_units() {
        for r in [1e5f32, 1e6] {
            // A wall whose near surface is 100 units in front of the origin.
            let c = [0.0, 0.0, -(r + 100.0)];
            let cases: Vec<_> = directions().into_iter().map(|d| ([0.0; 3], d, c, r)).collect();
            let worst = worst_error(&cases);
            std::println!("radius {r:e} at 100: worst relative hit-distance error {worst:e}");
            assert!(worst < 1e-5, "radius {r}: {worst}");
        }
    }

    #[test]
    fn smallpt_walls_from_inside_the_box() {
        // The left wall of smallpt's Cornell box, seen from the camera area.
        let c = [1e5 + 1.0, 40.8, 81.6];
        let cases: Vec<_> =
            directions().into_iter().map(|d| ([50.0, 52.0, 100.0], [-1.0, d[0], d[1]], c, 1e5)).collect();
        let worst = worst_error(&cases);
        std::println!("smallpt wall: worst relative error {worst:e}");
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn tiny_sphere_far_away() {
        let c = [1e3, 0.0, 0.0];
        let cases: Vec<_> = (0..40).map(|i| ([0.0; 3], [1.0, (i as f32 - 20.0) * 4e-8, 1e-7], c, 1e-3)).collect();
        let worst = worst_error(&cases);
        std::println!("radius 1e-3 at 1e3: worst relative error {worst:e}");
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn grazing_rays() {
        // Rays passing within a hair of the silhouette of a unit sphere.
        let cases: Vec<_> =
            (0..40).map(|i| ([-10.0, 1.0 - i as f32 * 1e-3, 0.0], [1.0, 0.0, 0.0], [0.0; 3], 1.0)).collect();
        let worst = worst_error(&cases);
        std::println!("grazing: worst relative error {worst:e}");
        assert!(worst < 1e-3, "{worst}");
    }

    #[test]
    fn rays_starting_on_the_surface_leave_it() {
        // From a point on the surface, going outwards: no hit; inwards: the far side.
        let c = Vec3::new(3.0, -2.0, 7.0);
        for k in 0..50 {
            let a = k as f32 * 0.37;
            let n = Vec3::new(libm::cosf(a), libm::sinf(a) * 0.6, 0.8 * libm::sinf(a * 1.3)).normalize();
            let p = c + n * 5.0;
            let eps = surface_offset(p);
            assert_eq!(ray_sphere(p + n * eps, n, c, 5.0, 0.0), MISS, "outward ray {k} hit its own sphere");
            let t = ray_sphere(p - n * eps, -n, c, 5.0, 0.0);
            assert!((t - 10.0).abs() < 1e-3, "inward ray {k}: {t}");
        }
    }

    /// The slab test culls no box the ray meets: random rays (near and far
    /// from the coordinate origin, at small and large scales, some
    /// parallel or nearly parallel to axes) against boxes with faces
    /// through a point of the ray (touching it, or holding it in a face),
    /// beside it and around it, judged in f64 (whose error is 2^-29 of
    /// f32's: a box it finds met is met, or misses by far less than the
    /// slab test's slack).
    #[test]
    fn slab_test_culls_no_box_the_ray_meets() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut met, mut checked) = (0, 0);
        for trial in 0..200_000 {
            let scale = 10f64.powf(next() * 9.0 - 3.0) as f32;
            let far = 10f64.powf(next() * 8.0) as f32 * (next() < 0.5) as u32 as f32;
            let mut unit = || Vec3::new(next() as f32 * 2.0 - 1.0, next() as f32 * 2.0 - 1.0, next() as f32 * 2.0 - 1.0);
            let o = unit() * far + unit() * scale;
            let mut d = unit().normalize_or(Vec3::X);
            for k in 0..3 {
                match (trial + k) % 7 {
                    0 => d[k] = 0.0,
                    1 => d[k] *= 1e-25,
                    _ => {}
                }
            }
            let d = d.normalize_or(Vec3::Z);
            let q = o + d * (next() as f32 * 10.0 * scale);
            let (mut lo, mut hi) = ([0f32; 3], [0f32; 3]);
            for k in 0..3 {
                let r = next();
                // A face through the point, or the point inside or beside.
                let (a, b) = (next() as f32 * scale, next() as f32 * scale);
                (lo[k], hi[k]) = match (r * 6.0) as u32 {
                    0 => (q[k], q[k] + a),
                    1 => (q[k] - a, q[k]),
                    2 => (q[k], q[k]),
                    3 => (q[k] + a * 1e-3, q[k] + a + b),
                    _ => (q[k] - a, q[k] + b),
                };
            }
            let t_max = if next() < 0.5 { MISS } else { (next() * 20.0) as f32 * scale };
            // The f64 slab test of the same ray and box, clipped to 0..t_max.
            let (mut near, mut farthest) = (0f64, t_max as f64);
            for k in 0..3 {
                let (o, d, lo, hi) = (o[k] as f64, d[k] as f64, lo[k] as f64, hi[k] as f64);
                if d == 0.0 {
                    if o < lo || o > hi {
                        farthest = -1.0;
                    }
                } else {
                    let (t0, t1) = ((lo - o) / d, (hi - o) / d);
                    near = near.max(t0.min(t1));
                    farthest = farthest.min(t0.max(t1));
                }
            }
            checked += 1;
            if near > farthest {
                continue;
            }
            met += 1;
            let root = ([lo[0].min(o.x) - scale, lo[1].min(o.y) - scale, lo[2].min(o.z) - scale], [hi[0].max(o.x) + scale, hi[1].max(o.y) + scale, hi[2].max(o.z) + scale]);
            for ray in [SlabRay::new(o, d), SlabRay::new(o, d).within(root.0, root.1)] {
                let (n, f) = slab_interval(lo, hi, &ray, t_max);
                assert!(n <= f, "trial {trial}: o {o:?} d {d:?} box {lo:?}..{hi:?} t_max {t_max}: culled ({n} > {f}); f64 {near}..{farthest}");
            }
        }
        // Most boxes are met (the check has teeth).
        assert!(met > checked / 4, "{met} of {checked}");
    }

    /// A ray along z, parallel to x and y: lying in a box's far face it
    /// stays in the box at any distance the root allows, while a box half a
    /// unit beside it, which the bias of `f32::MAX` let through, is culled.
    #[test]
    fn parallel_rays_within_the_root() {
        let meets = |ray: &SlabRay, lo: [f32; 3], hi: [f32; 3]| {
            let (near, far) = slab_interval(lo, hi, ray, MISS);
            near <= far
        };
        for scale in [1e-30f32, 1e-3, 1.0, 1e6, 1e30] {
            let root = ([-4.0 * scale, -4.0 * scale, -4.0 * scale], [4.0 * scale, 4.0 * scale, 4.0 * scale]);
            // The box's far faces in x and y hold the ray; it is entered at
            // about 7 scale (from z = -4) and left at 8.
            let (lo, hi) = ([0.0, 0.0, 3.0 * scale], [scale, scale, 4.0 * scale]);
            for d in [Vec3::Z, -Vec3::Z] {
                let o = Vec3::new(scale, scale, -4.0 * scale * d.z);
                let (lo, hi) = if d.z > 0.0 { (lo, hi) } else { ([lo[0], lo[1], -hi[2]], [hi[0], hi[1], -lo[2]]) };
                let ray = SlabRay::new(o, d);
                assert!(ray.is_parallel());
                let ray = ray.within(root.0, root.1);
                assert!(meets(&ray, lo, hi), "scale {scale}, d {d}: the ray lies in the box's faces");
                // Boxes half a unit of scale beside it in x, on either side
                // (the ray at x = scale): culled now; at scale 1 the one on
                // the side of x's far plane (by the sign of d.x, ±0) passed
                // with the bias of f32::MAX.
                let below = ([-scale, lo[1], lo[2]], [0.5 * scale, hi[1], hi[2]]);
                let above = ([1.5 * scale, lo[1], lo[2]], [2.5 * scale, hi[1], hi[2]]);
                for (b, side) in [(below, "below"), (above, "above")] {
                    assert!(!meets(&ray, b.0, b.1), "scale {scale}, d {d}: the box {side} the ray");
                }
                if scale == 1.0 {
                    let unbounded = SlabRay::new(o, d);
                    assert!(meets(&unbounded, below.0, below.1) || meets(&unbounded, above.0, above.1), "the old bias");
                }
            }
        }
        // No parallel axis: unchanged.
        let ray = SlabRay::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        assert!(!ray.is_parallel());
        assert_eq!(ray.within([-1.0; 3], [1.0; 3]).far_bias, [0.0; 3]);
    }

    #[test]
    fn boxes_with_axis_aligned_rays() {
        let node = Node { min: [0.0, 0.0, 0.0], left: 0, max: [1.0, 1.0, 1.0], right: 0 };
        let inv = safe_inverse(Vec3::new(1.0, 0.0, 0.0));
        assert!(ray_box(&node, Vec3::new(-1.0, 0.5, 0.5), inv, MISS));
        assert!(ray_box(&node, Vec3::new(-1.0, 0.0, 1.0), inv, MISS), "ray along an edge");
        assert!(!ray_box(&node, Vec3::new(-1.0, 1.5, 0.5), inv, MISS));
        assert!(!ray_box(&node, Vec3::new(2.0, 0.5, 0.5), inv, MISS), "box behind the ray");
    }
}
