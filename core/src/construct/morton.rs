//! Morton codes of primitive centroids (Karras 2012, section 4).
//!
//! Centroids are quantized to 21 bits per axis inside the *centroid* bounds
//! of the scene (tighter than the primitive bounds, so no bits are wasted),
//! and interleaved into a 63-bit key. The cells are cubes, sized by the
//! longest axis: stretching each axis to the full range instead makes a flat
//! scene split its thin axis as often as the long ones, which costs a
//! height-field terrain 22% of SAH in the LBVH and 6% after treelet
//! optimization (terrain:1000000: LBVH 89.6 -> 73.5, TRBVH 64.5 -> 60.9).
//!
//! Bit-exact on every device: the frame is precomputed on the host as an
//! offset and a scale ([`MortonFrame`]), so a kernel only does `c*0.5 - o`
//! (the halving is exact, so a fused multiply-add gives the same result) and
//! one multiply; GPU division, which Vulkan lets be inexact, is never used.
//! Halved coordinates keep scenes near ±f32::MAX from overflowing.
use glam::{UVec3, Vec3};

use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::BuildParams;

/// Quantization bits per axis.
pub const BITS_PER_AXIS: u32 = 21;
/// Significant bits of a Morton code.
pub const KEY_BITS: u32 = 3 * BITS_PER_AXIS;
/// Bits of the code kept in the key that the build sorts: all of them.
/// Fewer would mean fewer radix-sort passes (30 bits: four instead of
/// eight, half the sort's time), and keys equal in the bits kept stay in
/// primitive order. Measured on the H100 with `TREELET_MORTON_KEY_BITS=30`
/// (also 40, 48): the SAH of random:1000000 (424.40 LBVH / 394.15 TRBVH),
/// terrain:1002528 (73.52 / 60.96) and the bunny (3 674 triangles) is the
/// same to the last digit printed; but the 940 544-triangle bunny standing
/// in smallpt's room renders in 53.2 s instead of 0.35 s (1024x768, 64 spp),
/// because the room's walls (spheres of radius 1e5) set the Morton frame and
/// the whole bunny falls into a handful of ten-bit cells, where primitive
/// order decides the tree. The SAH, dominated by the walls, hardly shows it.
/// The sort takes about half the passes anyway, every bit kept: see
/// [`crate::construct::sort::ties`].
pub const SORTED_KEY_BITS: u32 = KEY_BITS;
const CELLS: f32 = (1u32 << BITS_PER_AXIS) as f32;
const MAX_CELL: f32 = CELLS - 1.0;

/// Offset and scale mapping a centroid to its quantization cell.
#[derive(Clone, Copy, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct MortonFrame {
    /// Half the lower corner of the centroid bounds.
    pub offset: Vec3,
    /// Cells per half unit, the same on every axis (cubic cells); zero on
    /// axes where all centroids agree.
    pub scale: Vec3,
}

impl MortonFrame {
    /// The frame of the given centroid bounds (empty bounds give scale 0).
    pub fn new(centroid_bounds: &Aabb) -> Self {
        if centroid_bounds.is_empty() {
            return Self { offset: Vec3::ZERO, scale: Vec3::ZERO };
        }
        let offset = centroid_bounds.lo() * 0.5;
        let half_extent = centroid_bounds.hi() * 0.5 - offset;
        let axis = |e: f32| {
            if e > 0.0 {
                let s = CELLS / e;
                // Extents near the smallest normal overflow the division.
                if s <= f32::MAX {
                    s
                } else {
                    f32::MAX
                }
            } else {
                0.0
            }
        };
        let s = axis(half_extent.max_element());
        let scale = Vec3::new(
            if half_extent.x > 0.0 { s } else { 0.0 },
            if half_extent.y > 0.0 { s } else { 0.0 },
            if half_extent.z > 0.0 { s } else { 0.0 },
        );
        Self { offset, scale }
    }

    /// The frame as stored in [`BuildParams`].
    pub fn from_params(p: &BuildParams) -> Self {
        Self { offset: Vec3::from_array(p.frame.min), scale: Vec3::from_array(p.frame.max) }
    }

    /// Stores the frame in [`BuildParams::frame`] (min = offset, max = scale).
    pub fn to_params(&self, p: &mut BuildParams) {
        p.frame.min = self.offset.to_array();
        p.frame.max = self.scale.to_array();
    }

    /// Cell of a centroid, each axis in `0..2^21`.
    #[inline]
    pub fn quantize(&self, centroid: Vec3) -> UVec3 {
        let cell = (centroid * 0.5 - self.offset) * self.scale;
        let cell = cell.max(Vec3::ZERO).min(Vec3::splat(MAX_CELL));
        UVec3::new(cell.x as u32, cell.y as u32, cell.z as u32)
    }

    /// The 63-bit Morton key of a centroid.
    ///
    /// ```
    /// use glam::Vec3;
    /// use treelet_core::{construct::morton::MortonFrame, Aabb};
    /// let frame = MortonFrame::new(&Aabb::new(Vec3::ZERO, Vec3::splat(10.0)));
    /// assert_eq!(frame.code(Vec3::ZERO), 0);
    /// assert!(frame.code(Vec3::new(1.0, 1.0, 1.0)) < frame.code(Vec3::new(9.0, 9.0, 9.0)));
    /// ```
    #[inline]
    pub fn code(&self, centroid: Vec3) -> u64 {
        let q = self.quantize(centroid);
        interleave(q.x, q.y, q.z)
    }
}

/// Spreads the low 21 bits of `v` to every third bit of a u64.
#[inline]
pub fn spread_bits(v: u32) -> u64 {
    let mut x = (v & 0x1f_ffff) as u64;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// 63-bit Morton key: x in the highest of each bit triple.
#[inline]
pub fn interleave(x: u32, y: u32, z: u32) -> u64 {
    (spread_bits(x) << 2) | (spread_bits(y) << 1) | spread_bits(z)
}

/// Kernel: the key of primitive `id` and its index as the sort's value;
/// where `params.zero_slots` is 1, `slots[id]` zeroed for `id < n - 1`: the
/// hierarchy's per-node arrival slots (the climbs' `ends`, the fit's
/// flags); and the first `params.zero_words` words of `zeroed` (the sort's
/// state), the `n` invocations striding over them. Zeroed here because a
/// fill dispatch of each was one more dispatch in the build (H100, 65 536
/// primitives: 3 µs each, of 0.157 ms).
pub fn morton_kernel(
    id: u32,
    params: &BuildParams,
    boxes: &[Aabb],
    keys: &mut [u64],
    values: &mut [u32],
    slots: &mut [u32],
    zeroed: &mut [u32],
) {
    if params.zero_slots != 0 && id + 1 < params.n {
        slots[id as usize] = 0;
    }
    if id < params.n {
        let mut w = id;
        while w < params.zero_words {
            zeroed[w as usize] = 0;
            w += params.n;
        }
    }
    if id < params.n {
        let frame = MortonFrame::from_params(params);
        keys[id as usize] = frame.code(boxes[id as usize].centroid()) >> params.key_shift;
        values[id as usize] = id;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spread_slow(v: u32) -> u64 {
        let mut out = 0u64;
        for bit in 0..21 {
            out |= (((v >> bit) & 1) as u64) << (3 * bit);
        }
        out
    }

    #[test]
    fn spread_matches_bit_loop() {
        for v in [0u32, 1, 2, 3, 0x1f_ffff, 0x15_5555, 0x0a_aaaa, 12345, 0xffff_ffff] {
            assert_eq!(spread_bits(v), spread_slow(v & 0x1f_ffff), "v = {v:#x}");
        }
    }

    #[test]
    fn corners_map_to_extreme_codes() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(3.0));
        let f = MortonFrame::new(&b);
        assert_eq!(f.code(Vec3::splat(-1.0)), 0);
        assert_eq!(f.code(Vec3::splat(3.0)), (1u64 << 63) - 1);
    }

    #[test]
    fn flat_and_point_frames_are_finite() {
        let flat = Aabb::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(1.0, 1.0, 5.0));
        let f = MortonFrame::new(&flat);
        assert_eq!(f.scale.z, 0.0);
        assert_eq!(f.quantize(Vec3::new(1.0, 0.0, 5.0)), UVec3::new(MAX_CELL as u32, 0, 0));
        let tiny = Aabb::new(Vec3::ZERO, Vec3::splat(1e-38));
        assert!(MortonFrame::new(&tiny).scale.is_finite());
    }

    #[test]
    fn cells_are_cubes_sized_by_the_longest_axis() {
        // 10 x 1 x 4: the long axis spans every cell, the others a share.
        let b = Aabb::new(Vec3::ZERO, Vec3::new(10.0, 1.0, 4.0));
        let f = MortonFrame::new(&b);
        assert_eq!(f.scale.x, f.scale.y);
        assert_eq!(f.scale.x, f.scale.z);
        let q = f.quantize(Vec3::new(10.0, 1.0, 4.0));
        assert_eq!(q.x, MAX_CELL as u32);
        assert_eq!(q.y, (CELLS / 10.0) as u32);
        assert_eq!(q.z, (CELLS * 0.4) as u32);
    }

    #[test]
    fn huge_frames_do_not_overflow() {
        let b = Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38));
        let f = MortonFrame::new(&b);
        assert_eq!(f.quantize(Vec3::splat(-3e38)), UVec3::ZERO);
        assert_eq!(f.quantize(Vec3::splat(3e38)), UVec3::splat(MAX_CELL as u32));
    }
}
