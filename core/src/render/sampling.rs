//! Sampling helpers shared by the integrator and the light sampler:
//! directions from uniform numbers, written out so that the GPU and the CPU
//! compute the same bits.
use glam::Vec3;

/// `(sin 2πu, cos 2πu)` by quadrant reduction and the Cephes minimax
/// polynomials (error about 1e-7). Written out, rather than the GPU's sin
/// and cos instructions, so that the GPU and the CPU compute the same
/// directions and their paths stay together.
#[inline]
pub fn sin_cos_turns(u: f32) -> (f32, f32) {
    let a = u * 4.0;
    let q = libm::roundf(a);
    let r = (a - q) * core::f32::consts::FRAC_PI_2;
    let r2 = r * r;
    let s = r + r * r2 * (-1.666_665_5e-1 + r2 * (8.332_161e-3 + r2 * -1.951_529_6e-4));
    let c = 1.0 - 0.5 * r2 + r2 * r2 * (4.166_664_6e-2 + r2 * (-1.388_731_6e-3 + r2 * 2.443_315_7e-5));
    match (q as i32) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// A cosine-weighted direction about the unit normal `w` (smallpt's diffuse
/// bounce) from two uniform numbers.
#[inline]
pub fn cosine_direction(w: Vec3, u1: f32, u2: f32) -> Vec3 {
    let (sin, cos) = sin_cos_turns(u1);
    let r2s = libm::sqrtf(u2);
    let u = (if w.x.abs() > 0.1 { Vec3::Y } else { Vec3::X }).cross(w).normalize();
    let v = w.cross(u);
    (u * cos * r2s + v * sin * r2s + w * libm::sqrtf(1.0 - u2)).normalize()
}

/// Rec. 709 luminance.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}
