//! The part of a triangle inside a box, and its area: what the end-point
//! overlap metric ([`super::epo`]) sums. In f64 and without allocation (Sutherland & Hodgman 1974: the triangle is
//! cut by the box's six planes in turn, each cut adding at most one
//! vertex, so nine suffice).

/// Most vertices of a triangle cut by six planes.
const MAX_VERTICES: usize = 9;

/// Area of the part of the triangle `v` inside the box `lo..hi` (its faces
/// included); 0 where they do not meet.
pub fn triangle_area_in_box(v: [[f64; 3]; 3], lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let mut poly = [[0.0f64; 3]; MAX_VERTICES];
    poly[..3].copy_from_slice(&v);
    let mut len = 3;
    for axis in 0..3 {
        len = cut(&mut poly, len, axis, lo[axis], false);
        len = cut(&mut poly, len, axis, hi[axis], true);
        if len < 3 {
            return 0.0;
        }
    }
    polygon_area(&poly[..len])
}

/// Keeps the part of the convex polygon `poly[..len]` below (`below`) or
/// above `pos` on `axis`; its new vertex count.
fn cut(poly: &mut [[f64; 3]; MAX_VERTICES], len: usize, axis: usize, pos: f64, below: bool) -> usize {
    let inside = |p: &[f64; 3]| if below { p[axis] <= pos } else { p[axis] >= pos };
    let mut out = [[0.0f64; 3]; MAX_VERTICES];
    let mut n = 0;
    for i in 0..len {
        let (p, q) = (poly[i], poly[(i + 1) % len]);
        if inside(&p) && n < MAX_VERTICES {
            out[n] = p;
            n += 1;
        }
        if inside(&p) != inside(&q) && n < MAX_VERTICES {
            let t = (pos - p[axis]) / (q[axis] - p[axis]);
            let mut x = [0.0; 3];
            for k in 0..3 {
                x[k] = p[k] + (q[k] - p[k]) * t;
            }
            x[axis] = pos; // on the plane exactly
            out[n] = x;
            n += 1;
        }
    }
    *poly = out;
    n
}

/// Area of a planar convex polygon: half the length of the sum of its fan's
/// cross products.
fn polygon_area(poly: &[[f64; 3]]) -> f64 {
    let mut s = [0.0f64; 3];
    for i in 1..poly.len().saturating_sub(1) {
        let c = cross(sub(poly[i], poly[0]), sub(poly[i + 1], poly[0]));
        for k in 0..3 {
            s[k] += c[k];
        }
    }
    0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
}

/// Area of a triangle.
pub fn triangle_area(v: [[f64; 3]; 3]) -> f64 {
    polygon_area(&v)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];

    #[test]
    fn a_box_around_the_triangle_keeps_all_of_it() {
        assert_eq!(triangle_area_in_box(T, [-1.0; 3], [3.0; 3]), 2.0);
        assert_eq!(triangle_area(T), 2.0);
    }

    #[test]
    fn a_unit_box_at_the_corner_keeps_a_unit_square() {
        let a = triangle_area_in_box(T, [0.0, 0.0, -1.0], [1.0, 1.0, 1.0]);
        assert!((a - 1.0).abs() < 1e-12, "{a}");
    }

    #[test]
    fn boxes_beside_or_flat_against_the_plane_keep_what_they_should() {
        assert_eq!(triangle_area_in_box(T, [3.0, 0.0, -1.0], [4.0, 1.0, 1.0]), 0.0);
        assert_eq!(triangle_area_in_box(T, [0.0, 0.0, 0.5], [2.0, 2.0, 1.0]), 0.0);
        // A box of zero thickness on the triangle's plane holds its part.
        let a = triangle_area_in_box(T, [1.0, 0.0, 0.0], [2.0, 2.0, 0.0]);
        assert!((a - 0.5).abs() < 1e-12, "{a}");
    }

    #[test]
    fn a_slanted_triangle_cut_in_half_by_a_plane() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let whole = triangle_area(t);
        let left = triangle_area_in_box(t, [-1.0; 3], [0.5, 2.0, 2.0]);
        let right = triangle_area_in_box(t, [0.5, -1.0, -1.0], [2.0; 3]);
        assert!((left + right - whole).abs() < 1e-12);
        // The part past x = 0.5 is a quarter of the triangle (scaled by 1/2 on both legs).
        assert!((right - whole / 4.0).abs() < 1e-12, "{right} of {whole}");
    }
}
