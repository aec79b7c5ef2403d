//! Scenes: parsing a scene name, generating random scenes, checking input.
use anyhow::{bail, Context as _, Result};
use rand::{Rng, SeedableRng};
use treelet_core::layout::Sphere;

/// A named set of primitives.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub spheres: Vec<Sphere>,
}

/// Interior of smallpt's Cornell box, where random scenes place spheres.
pub const RANDOM_BOX_MIN: [f32; 3] = [1.0, 0.0, 0.0];
pub const RANDOM_BOX_MAX: [f32; 3] = [99.0, 81.6, 170.0];

impl Scene {
    /// Parses a scene name: `random:N[:SEED]`.
    pub fn from_spec(spec: &str) -> Result<Scene> {
        let mut parts = spec.split(':');
        match parts.next() {
            Some("random") => {
                let n = parts.next().with_context(|| format!("scene `{spec}`: expected random:N[:SEED]"))?;
                let n: usize = n.parse().with_context(|| format!("scene `{spec}`: `{n}` is not a primitive count"))?;
                let seed = match parts.next() {
                    Some(s) => s.parse().with_context(|| format!("scene `{spec}`: `{s}` is not a seed"))?,
                    None => 1,
                };
                if parts.next().is_some() {
                    bail!("scene `{spec}`: expected random:N[:SEED]");
                }
                if n > crate::lbvh::MAX_PRIMITIVES as usize {
                    bail!("scene `{spec}`: {n} primitives, at most {} are supported", crate::lbvh::MAX_PRIMITIVES);
                }
                Ok(Scene { name: spec.to_string(), spheres: random_spheres(n, seed) })
            }
            _ => bail!("unknown scene `{spec}`: expected random:N[:SEED]"),
        }
    }
}

/// `n` spheres with uniform random centres inside the Cornell box and random
/// radii, sized so that the spheres fill a similar fraction of the box
/// whatever `n`. Deterministic for a given seed.
pub fn random_spheres(n: usize, seed: u64) -> Vec<Sphere> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let size: Vec<f32> = (0..3).map(|k| RANDOM_BOX_MAX[k] - RANDOM_BOX_MIN[k]).collect();
    let volume: f32 = size.iter().product();
    // Mean spacing between centres; radii up to a third of it.
    let spacing = (volume / n.max(1) as f32).cbrt();
    (0..n)
        .map(|_| {
            let c = [0, 1, 2].map(|k| RANDOM_BOX_MIN[k] + rng.random::<f32>() * size[k]);
            Sphere::new(c, spacing * rng.random_range(0.05..0.33))
        })
        .collect()
}

/// Rejects spheres a build cannot use, naming the first bad one: non-finite
/// centre or radius, or a negative radius.
pub fn validate_spheres(spheres: &[Sphere]) -> Result<()> {
    for (i, s) in spheres.iter().enumerate() {
        if let Some(k) = s.center.iter().position(|c| !c.is_finite()) {
            bail!(
                "sphere {i}: centre coordinate {} is {} (every coordinate must be finite)",
                "xyz".as_bytes()[k] as char,
                s.center[k]
            );
        }
        if !s.radius.is_finite() || s.radius < 0.0 {
            bail!("sphere {i}: radius is {} (must be finite and non-negative)", s.radius);
        }
        // A box corner (centre ± radius) must stay finite too.
        if s.center.iter().any(|c| !(c.abs() + s.radius).is_finite()) {
            bail!("sphere {i}: its bounding box overflows f32 (centre {:?}, radius {})", s.center, s.radius);
        }
    }
    Ok(())
}
