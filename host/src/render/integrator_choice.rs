//! `--integrator auto`: next-event estimation alone, or with light paths
//! for the caustics it cannot find, whichever a short pilot measures to
//! reach less error in the same time on this scene and these devices
//! (light paths won on the disk-lit room, 0.89x NEE's error at equal time on
//! an H100, and lost 4x on cornell, whose lamp is mostly inside the ceiling:
//! no rule of thumb tells the two apart, a measurement does).
//!
//! The pilot renders a few samples of every pixel twice with each
//! integrator, with seeds of its own ([`pilot_spp`]). Half the mean squared difference of
//! the two images is the variance of one of them; for an unbiased estimator
//! variance times time is what a given error costs, so the integrator with
//! the smaller product wins. The pilot's samples are thrown away: the image
//! is the chosen integrator's, as if it had been named.
use anyhow::Result;

use super::devices::render_on_devices;
use super::image_io::HdrImage;
use super::run::Control;
use super::settings::{Integrator, RenderSettings};
use super::variant::SceneFeatures;
use crate::runtime::device::Device;
use crate::scene::Scene;

/// Fewest samples per pixel of a pilot image.
pub const PILOT_MIN_SPP: u32 = 4;

/// Fewest paths (pixels times samples) of a pilot image: light paths'
/// errors come from rare heavy paths, and a small pilot misses them (on
/// cornell at 64x48, 4 spp measured light paths at 1.02x NEE's error; at
/// 256x192, 1.9 to 4.2x, as full renders measure 4x).
pub const PILOT_PATHS: u64 = 1 << 17;

/// The pilot's four images take at most this share of the render's samples.
pub const PILOT_SHARE: u32 = 8;

/// Added to the render's seed for the two pilot images of each integrator.
const PILOT_SEEDS: [u32; 2] = [0x5eed_0001, 0x5eed_0002];

/// What the pilot measured of one integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    pub integrator: Integrator,
    /// Variance of a pixel channel's estimate from one sample per pixel.
    pub variance: f64,
    /// Kernel milliseconds per sample of every pixel.
    pub ms_per_spp: f64,
}

impl Measured {
    /// Variance times time: what a given error costs.
    pub fn cost(&self) -> f64 {
        self.variance * self.ms_per_spp
    }
}

/// The integrator chosen, and why.
#[derive(Clone, Debug)]
pub struct Choice {
    pub integrator: Integrator,
    pub reason: String,
    /// The pilot's measurements (empty when no pilot ran).
    pub measured: Vec<Measured>,
}

/// Samples per pixel of each pilot image for `settings`, if a pilot is
/// worth it: [`PILOT_PATHS`] paths an image, at least [`PILOT_MIN_SPP`],
/// and the four images within 1/[`PILOT_SHARE`] of the render's samples.
pub fn pilot_spp(settings: &RenderSettings) -> Option<u32> {
    let pixels = (settings.width as u64 * settings.height as u64).max(1);
    let spp = PILOT_PATHS.div_ceil(pixels).max(PILOT_MIN_SPP as u64);
    (4 * PILOT_SHARE as u64 * spp <= settings.spp as u64).then_some(spp as u32)
}

/// Chooses between NEE and NEE with light paths for `settings` (whose
/// integrator is ignored) on `devices`: without mirrors or glass lit by a
/// lamp, or where [`pilot_spp`] says a pilot is not worth it, NEE without
/// one; else by the pilot (see the module doc).
pub fn choose(devices: &[Device], scene: &Scene, settings: &RenderSettings) -> Result<Choice> {
    let f = SceneFeatures::of(scene);
    if f.mirror + f.glass == 0 || f.emissive == 0 {
        let reason = "the scene has no mirrors or glass with lights, so no caustics for light paths".to_string();
        return Ok(Choice { integrator: Integrator::Nee, reason, measured: Vec::new() });
    }
    if scene.camera.lens_radius > 0.0 {
        let reason = "light paths link to a pinhole camera, and this camera has a lens".to_string();
        return Ok(Choice { integrator: Integrator::Nee, reason, measured: Vec::new() });
    }
    let Some(spp) = pilot_spp(settings) else {
        let reason = format!(
            "a pilot of both (four images of {} paths or more) would take over 1/{PILOT_SHARE} of this render's samples",
            PILOT_PATHS
        );
        return Ok(Choice { integrator: Integrator::Nee, reason, measured: Vec::new() });
    };
    let mut measured = Vec::new();
    for integrator in [Integrator::Nee, Integrator::Caustics] {
        let mut images = Vec::new();
        let mut ms = 0.0;
        for add in PILOT_SEEDS {
            let pilot = RenderSettings {
                spp,
                seed: settings.seed.wrapping_add(add),
                integrator,
                error_each_pass: false,
                first_sample: 0,
                ..*settings
            };
            let control = Control { stop: None, checkpoint: None, resume: None, inject: None };
            let result = render_on_devices(devices, scene, &pilot, None, control, |_| {})?;
            ms += result.render_ms;
            images.push(result.image);
        }
        let variance = half_mean_squared_difference(&images[0], &images[1]) * spp as f64;
        measured.push(Measured { integrator, variance, ms_per_spp: ms / (2 * spp) as f64 });
    }
    let (nee, caustics) = (measured[0], measured[1]);
    let integrator = pick(&nee, &caustics);
    let reason = format!(
        "a pilot of {spp} spp, twice each: light paths would give {:.2}x nee's error in equal time \
         (variance per sample {:.3e} against {:.3e}, {:.3} against {:.3} ms a sample of every pixel)",
        (caustics.cost() / nee.cost().max(f64::MIN_POSITIVE)).sqrt(),
        caustics.variance,
        nee.variance,
        caustics.ms_per_spp,
        nee.ms_per_spp
    );
    Ok(Choice { integrator, reason, measured })
}

/// The integrator of the two that costs less for the same error; NEE on a
/// tie or when a measurement is not a number.
pub fn pick(nee: &Measured, caustics: &Measured) -> Integrator {
    if caustics.cost() < nee.cost() {
        Integrator::Caustics
    } else {
        Integrator::Nee
    }
}

/// Half the mean squared difference of two images' channels: the variance
/// of either, when they are independent estimates of the same image.
fn half_mean_squared_difference(a: &HdrImage, b: &HdrImage) -> f64 {
    let (rmse, _) = super::sums::image_error(a.pixels.iter().map(|p| p.map(f64::from)), b);
    rmse * rmse / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(integrator: Integrator, variance: f64, ms_per_spp: f64) -> Measured {
        Measured { integrator, variance, ms_per_spp }
    }

    /// Less variance wins at equal time, less time at equal variance; what
    /// counts is the product, not either alone; a NaN never picks light paths.
    #[test]
    fn the_cheaper_error_wins() {
        let nee = m(Integrator::Nee, 1.0, 1.0);
        assert_eq!(pick(&nee, &m(Integrator::Caustics, 0.5, 1.0)), Integrator::Caustics);
        assert_eq!(pick(&nee, &m(Integrator::Caustics, 1.0, 0.8)), Integrator::Caustics);
        assert_eq!(pick(&nee, &m(Integrator::Caustics, 0.7, 1.5)), Integrator::Nee);
        assert_eq!(pick(&nee, &m(Integrator::Caustics, 1.0, 1.0)), Integrator::Nee);
        assert_eq!(pick(&nee, &m(Integrator::Caustics, f64::NAN, 1.0)), Integrator::Nee);
    }

    /// A pilot image has 2^17 paths or more, and the pilot stays within an
    /// eighth of the render's samples, or there is none.
    #[test]
    fn pilot_size() {
        let at = |width, height, spp| RenderSettings {
            width,
            height,
            spp,
            seed: 0,
            accel: crate::bvh::tree::Accel::Auto,
            layout: crate::bvh::layout::Layout::Auto,
            kernel: super::super::variant::KernelChoice::Auto,
            integrator: Integrator::Nee,
            sampler: super::super::settings::Sampler::Sobol,
            error_each_pass: false,
            first_sample: 0,
        };
        assert_eq!(pilot_spp(&at(1024, 768, 1024)), Some(4));
        assert_eq!(pilot_spp(&at(1024, 768, 127)), None);
        assert_eq!(pilot_spp(&at(1024, 768, 128)), Some(4));
        assert_eq!(pilot_spp(&at(128, 96, 256)), None);
        assert_eq!(pilot_spp(&at(128, 96, 1024)), Some(11));
    }

    /// Two images that differ by d in every channel have variance d²/2.
    #[test]
    fn variance_from_two_images() {
        let a = HdrImage { width: 2, height: 1, pixels: vec![[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]] };
        let b = HdrImage { width: 2, height: 1, pixels: vec![[1.5, 2.5, 3.5], [0.5, -0.5, 0.5]] };
        assert!((half_mean_squared_difference(&a, &b) - 0.125).abs() < 1e-12);
    }
}
