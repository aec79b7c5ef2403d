//! Per-pixel sums (radiance r, g, b and squared luminance): how parts of a
//! render add up, their image of means, and the error of an image against a
//! reference or from its sample variance.
use rayon::prelude::*;
use treelet_core::render::sampling::luminance;

use super::image_io::HdrImage;
use super::outcome::PassRow;

/// Adds per-pixel sums (radiance r, g, b and squared luminance) of one
/// part of a render into `total`, in f64 so that many parts add without
/// loss (devices, `treelet merge`).
pub fn add_sums<T: Copy + Into<f64> + Sync>(total: &mut [[f64; 4]], part: &[[T; 4]]) {
    // Each pixel on its own: in parallel, and the same at any thread count.
    total.par_iter_mut().zip(part).for_each(|(t, p)| {
        for k in 0..4 {
            t[k] += p[k].into();
        }
    });
}

/// Pixels per task where a whole-image sum is split over threads: fixed, so
/// that the sum is added in the same order on every machine.
const SUM_CHUNK: usize = 4096;

/// `f` summed over `items`, in parallel, and in an order that depends on
/// nothing but the items (chunks of [`SUM_CHUNK`], then the chunks' sums in
/// order): an error figure is the same on every run.
fn sum_in_order<T: Sync, const N: usize>(items: &[T], f: impl Fn(&T) -> [f64; N] + Sync) -> [f64; N] {
    let partial: Vec<[f64; N]> = items
        .par_chunks(SUM_CHUNK)
        .map(|c| {
            c.iter().fold([0.0; N], |mut acc, x| {
                let v = f(x);
                for k in 0..N {
                    acc[k] += v[k];
                }
                acc
            })
        })
        .collect();
    partial.iter().fold([0.0; N], |mut acc, v| {
        for k in 0..N {
            acc[k] += v[k];
        }
        acc
    })
}

/// The image of mean radiance from per-pixel sums over `samples` samples.
pub fn mean_image<T: Copy + Into<f64> + Sync>(width: u32, height: u32, sums: &[[T; 4]], samples: u32) -> HdrImage {
    let n = samples as f64;
    HdrImage { width, height, pixels: sums.par_iter().map(|s| [s[0], s[1], s[2]].map(|v| (v.into() / n) as f32)).collect() }
}

/// Root mean square error (per channel) of `image` against `reference`,
/// and the mean of `(x - ref)² / (ref² + 0.01)`: how every render and
/// `treelet compare` score an image. Images must have the same size.
pub fn image_error(image: impl Iterator<Item = [f64; 3]>, reference: &HdrImage) -> (f64, f64) {
    let (mut se, mut rel, mut count) = (0.0f64, 0.0f64, 0usize);
    for (x, rp) in image.zip(&reference.pixels) {
        for k in 0..3 {
            let y = rp[k] as f64;
            se += (x[k] - y) * (x[k] - y);
            rel += (x[k] - y) * (x[k] - y) / (y * y + 0.01);
        }
        count += 3;
    }
    ((se / count.max(1) as f64).sqrt(), rel / count.max(1) as f64)
}

/// `times`: elapsed, wall and kernel seconds (see [`PassRow`]).
pub(super) fn error_row(
    pass: u32,
    spp: u32,
    times: (f64, f64, f64),
    sums: &[[f32; 4]],
    reference: Option<&HdrImage>,
) -> PassRow {
    let n = spp as f64;
    let (elapsed_s, wall_s, kernel_s) = times;
    let mut row = PassRow { pass, spp, elapsed_s, wall_s, kernel_s, rmse: None, rel_mse: None, mean_std_error: None };
    match reference {
        Some(r) => {
            let (rmse, rel) = image_error(sums.iter().map(|s| [0, 1, 2].map(|k| s[k] as f64 / n)), r);
            row.rmse = Some(rmse);
            row.rel_mse = Some(rel);
        }
        None if spp >= 2 => {
            let [total] = sum_in_order(sums, |s| {
                let mean = luminance(glam::Vec3::new(s[0], s[1], s[2])) as f64 / n;
                let var = ((s[3] as f64 - n * mean * mean) / (n - 1.0)).max(0.0);
                [(var / n).sqrt()]
            });
            row.mean_std_error = Some(total / sums.len() as f64);
        }
        None => {}
    }
    row
}
