//! Developers' knobs, as one value: the `TREELET_*` environment variables
//! that override a build's or the runtime's measured defaults (to measure
//! against them, or to cap memory on a shared machine).
//!
//! The variables are read and checked once, by [`Tuning::from_env`]: a value
//! that does not parse is an error that names the variable, never a knob
//! silently ignored. The library itself reads no environment: it takes the
//! [`Tuning`] that was [installed](Tuning::install) for the process (the
//! `treelet` command installs the environment's at start), or the shipped
//! defaults ([`Tuning::default`]) where none was. An engine that embeds the
//! library installs one of its own, or none:
//!
//! ```
//! use treelet::tuning::Tuning;
//! // Split no triangles, whatever the builder's default.
//! let tuning = Tuning { splits: Some(0.0), ..Tuning::default() };
//! assert_eq!(tuning.splits, Some(0.0));
//! // tuning.install() makes it the process's, once.
//! ```
use std::path::PathBuf;
use std::sync::OnceLock;


/// A `TREELET_*` variable whose value does not parse.
#[derive(Debug, thiserror::Error)]
#[error("{name}={value}: {why}")]
pub struct TuningError {
    /// The variable.
    pub name: &'static str,
    /// Its value (lossy where it is not UTF-8).
    pub value: String,
    /// What was expected.
    pub why: String,
}

/// Where compiled pipelines are cached (`TREELET_PIPELINE_CACHE`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum PipelineCache {
    /// `$XDG_CACHE_HOME/treelet`, else `$HOME/.cache/treelet`.
    #[default]
    Default,
    /// No cache (`off`).
    Off,
    /// This folder.
    At(PathBuf),
}

/// The radix sort's tiles, forced (`TREELET_SORT_TILES`; the builders map
/// it onto `crate::bvh::sort::SortTiles`, a floor above this one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SortTiles {
    Small,
    Large,
    Multisplit,
    MultisplitSmall,
    MultisplitMedium,
}

/// The LBVH's hierarchy, forced (`TREELET_HIERARCHY`; mapped onto
/// `crate::bvh::lbvh::Hierarchy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hierarchy {
    /// `radix`: the radix tree, then the fit.
    Radix,
    /// `agglomerative`: both in one bottom-up pass.
    Agglomerative,
    /// `subgroup`: the same, the lowest levels within subgroups.
    Subgroup,
    /// `hploc`: H-PLOC's tree (so `--accel trbvh` restructures H-PLOC's
    /// tree instead of the radix tree).
    Hploc,
}

/// Timing of the TRBVH's heights (`TREELET_PROFILE_LEVELS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProfileLevels {
    /// Each height as a stage of its own (any value but `empty`).
    Timed,
    /// The same, with an empty launch after each height (`empty`).
    WithEmptyLaunches,
}

/// Every override, `None` (or the shipped default) where unset. Each field
/// names its variable.
#[derive(Clone, Debug, PartialEq)]
pub struct Tuning {
    /// `TREELET_MAX_MEMORY`: caps the host memory work may count on
    /// (`8GiB`, `512M`, bytes: see [`parse_bytes`]).
    pub max_memory: Option<u64>,
    /// `TREELET_PIPELINE_CACHE`: a folder, or `off`.
    pub pipeline_cache: PipelineCache,
    /// `TREELET_SUBGROUP_PARTITIONED=0`: ignore NVIDIA's subgroup partition
    /// instruction where the device has it.
    pub subgroup_partitioned: bool,
    /// `TREELET_SORT_LOOK_BACK=0`: the radix sort without decoupled look-back.
    pub sort_look_back: bool,
    /// `TREELET_SORT_MATCH=ballots`: the sort matches digits by ballots
    /// even where the partition instruction is there.
    pub sort_match_ballots: bool,
    /// `TREELET_SORT_TILES=small|large|multisplit|multisplit-small|multisplit-medium`.
    pub sort_tiles: Option<SortTiles>,
    /// `TREELET_SORT_HIGH_FIRST=0`: sort the low digits first.
    pub sort_high_first: bool,
    /// `TREELET_MORTON_KEY_BITS`: bits of the Morton keys sorted (1 to 64).
    pub morton_key_bits: Option<u32>,
    /// `TREELET_HIERARCHY=radix|agglomerative|subgroup|hploc`.
    pub hierarchy: Option<Hierarchy>,
    /// `TREELET_HPLOC_KEEP`: clusters an H-PLOC range keeps.
    pub hploc_keep: Option<u32>,
    /// `TREELET_HPLOC_RADIUS`: how far apart two merged clusters may be (0: any).
    pub hploc_radius: Option<u32>,
    /// `TREELET_SPLITS`: extra references triangle splitting may add, as a
    /// fraction of the triangles, for every builder (0: none).
    pub splits: Option<f32>,
    /// `TREELET_TREELETS=ROUNDS,GAMMA,MAX_LEAF`: the TRBVH's rounds.
    pub treelets: Option<(u32, u32, u32)>,
    /// `TREELET_REINSERT`: reinsertion iterations after the TRBVH's rounds.
    pub reinsert: Option<u32>,
    /// `TREELET_REINSERT_CLIMB`: ancestors a reinsertion search climbs.
    pub reinsert_climb: Option<u32>,
    /// `TREELET_REINSERT_LEAVES=0`: reinsertion moves internal nodes only.
    pub reinsert_leaves: bool,
    /// `TREELET_SINGLE_HEIGHTS`: the TRBVH's heights run by one invocation.
    pub single_heights: Option<u32>,
    /// `TREELET_PROFILE_LEVELS` (any value; `empty` adds empty launches).
    pub profile_levels: Option<ProfileLevels>,
    /// `TREELET_PROFILE_REINSERT` (any value): print the moves each
    /// reinsertion iteration made.
    pub profile_reinsert: bool,
    /// `TREELET_WIDE_COSTS=NODE,PRIM`: the 8-wide layout's cost model.
    pub wide_costs: Option<(f32, f32)>,
}

impl Default for Tuning {
    /// The shipped defaults: no override.
    fn default() -> Self {
        Tuning {
            max_memory: None,
            pipeline_cache: PipelineCache::Default,
            subgroup_partitioned: true,
            sort_look_back: true,
            sort_match_ballots: false,
            sort_tiles: None,
            sort_high_first: true,
            morton_key_bits: None,
            hierarchy: None,
            hploc_keep: None,
            hploc_radius: None,
            splits: None,
            treelets: None,
            reinsert: None,
            reinsert_climb: None,
            reinsert_leaves: true,
            single_heights: None,
            profile_levels: None,
            profile_reinsert: false,
            wide_costs: None,
        }
    }
}

static INSTALLED: OnceLock<Tuning> = OnceLock::new();

impl Tuning {
    /// The knobs the `TREELET_*` variables set; an empty variable counts as
    /// unset.
    pub fn from_env() -> Result<Tuning, TuningError> {
        Tuning::from_vars(|name| std::env::var_os(name).map(|v| v.to_string_lossy().into_owned()))
    }

    /// [`Tuning::from_env`] over any source of variables (for tests).
    pub fn from_vars(var: impl Fn(&str) -> Option<String>) -> Result<Tuning, TuningError> {
        let mut t = Tuning::default();
        let get = |name: &'static str| var(name).filter(|v| !v.trim().is_empty()).map(|v| (name, v));
        if let Some((name, v)) = get("TREELET_MAX_MEMORY") {
            t.max_memory = Some(parse_bytes(&v).map_err(|why| err(name, &v, why))?);
        }
        if let Some((_, v)) = get("TREELET_PIPELINE_CACHE") {
            t.pipeline_cache = if v == "off" { PipelineCache::Off } else { PipelineCache::At(PathBuf::from(v)) };
        }
        if let Some(v) = get("TREELET_SUBGROUP_PARTITIONED") {
            t.subgroup_partitioned = switch(v)?;
        }
        if let Some(v) = get("TREELET_SORT_LOOK_BACK") {
            t.sort_look_back = switch(v)?;
        }
        if let Some((name, v)) = get("TREELET_SORT_MATCH") {
            t.sort_match_ballots = match v.trim() {
                "ballots" => true,
                "partitioned" => false,
                _ => return Err(err(name, &v, "expected `ballots` or `partitioned`")),
            };
        }
        if let Some((name, v)) = get("TREELET_SORT_TILES") {
            t.sort_tiles = Some(match v.trim() {
                "small" => SortTiles::Small,
                "large" => SortTiles::Large,
                "multisplit" => SortTiles::Multisplit,
                "multisplit-small" => SortTiles::MultisplitSmall,
                "multisplit-medium" => SortTiles::MultisplitMedium,
                _ => return Err(err(name, &v, "expected small, large, multisplit, multisplit-small or multisplit-medium")),
            });
        }
        if let Some(v) = get("TREELET_SORT_HIGH_FIRST") {
            t.sort_high_first = switch(v)?;
        }
        if let Some(v) = get("TREELET_MORTON_KEY_BITS") {
            t.morton_key_bits = Some(number_in(v, 1..=64)?);
        }
        if let Some((name, v)) = get("TREELET_HIERARCHY") {
            t.hierarchy = Some(match v.trim() {
                "radix" => Hierarchy::Radix,
                "agglomerative" => Hierarchy::Agglomerative,
                "subgroup" => Hierarchy::Subgroup,
                "hploc" => Hierarchy::Hploc,
                _ => return Err(err(name, &v, "expected radix, agglomerative, subgroup or hploc")),
            });
        }
        if let Some(v) = get("TREELET_HPLOC_KEEP") {
            t.hploc_keep = Some(number_in(v, 1..=32)?);
        }
        if let Some(v) = get("TREELET_HPLOC_RADIUS") {
            t.hploc_radius = Some(number_in(v, 0..=u32::MAX)?);
        }
        if let Some((name, v)) = get("TREELET_SPLITS") {
            let budget: f32 = v.trim().parse().map_err(|_| err(name, &v, "expected a number >= 0"))?;
            if !(budget.is_finite() && budget >= 0.0) {
                return Err(err(name, &v, "expected a finite number >= 0"));
            }
            t.splits = Some(budget);
        }
        if let Some((name, v)) = get("TREELET_TREELETS") {
            let n: Vec<u32> = v.split(',').map(|x| x.trim().parse().ok()).collect::<Option<_>>().unwrap_or_default();
            match n[..] {
                [rounds, gamma, max_leaf] if (1..=1024).contains(&max_leaf) => t.treelets = Some((rounds, gamma, max_leaf)),
                _ => return Err(err(name, &v, "expected ROUNDS,GAMMA,MAX_LEAF, whole numbers, MAX_LEAF from 1 to 1024")),
            }
        }
        if let Some(v) = get("TREELET_REINSERT") {
            // As `--reinsert`: each iteration is a pass over the tree, and
            // four billion of them never end.
            t.reinsert = Some(number_in(v, 0..=64)?);
        }
        if let Some(v) = get("TREELET_REINSERT_CLIMB") {
            t.reinsert_climb = Some(number_in(v, 0..=u32::MAX)?);
        }
        if let Some(v) = get("TREELET_REINSERT_LEAVES") {
            t.reinsert_leaves = switch(v)?;
        }
        if let Some(v) = get("TREELET_SINGLE_HEIGHTS") {
            t.single_heights = Some(number_in(v, 0..=u32::MAX)?);
        }
        if let Some((_, v)) = get("TREELET_PROFILE_LEVELS") {
            t.profile_levels = Some(if v.trim() == "empty" { ProfileLevels::WithEmptyLaunches } else { ProfileLevels::Timed });
        }
        t.profile_reinsert = get("TREELET_PROFILE_REINSERT").is_some();
        if let Some((name, v)) = get("TREELET_WIDE_COSTS") {
            let costs = v.split_once(',').and_then(|(a, b)| Some((a.trim().parse::<f32>().ok()?, b.trim().parse::<f32>().ok()?)));
            match costs {
                Some((node, prim)) if node.is_finite() && prim.is_finite() && node >= 0.0 && prim >= 0.0 => {
                    t.wide_costs = Some((node, prim))
                }
                _ => return Err(err(name, &v, "expected NODE,PRIM, two finite numbers >= 0")),
            }
        }
        Ok(t)
    }

    /// Makes this the process's tuning, which every build and device takes
    /// from then on. Only the first call counts: an error hands back the
    /// tuning of a later one, so that a caller knows it was not taken.
    pub fn install(self) -> Result<(), Tuning> {
        INSTALLED.set(self)
    }

    /// The process's tuning: the installed one, else the defaults.
    pub fn current() -> &'static Tuning {
        static DEFAULTS: OnceLock<Tuning> = OnceLock::new();
        INSTALLED.get().unwrap_or_else(|| DEFAULTS.get_or_init(Tuning::default))
    }
}

/// A size in bytes: a number, then an optional unit (any case): `B`; `K`,
/// `M`, `G`, `T` and `KiB`, `MiB`, `GiB`, `TiB` as powers of 1024; `KB`,
/// `MB`, `GB`, `TB` as powers of 1000. At least one byte.
pub fn parse_bytes(text: &str) -> std::result::Result<u64, String> {
    let t = text.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (number, unit) = (t[..split].trim(), t[split..].trim());
    let value: f64 = number.parse().map_err(|_| format!("`{t}` does not start with a number (use 8GiB, 512M or 1000000000)"))?;
    let scale: f64 = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kib" => 1024.0,
        "m" | "mib" => 1024f64.powi(2),
        "g" | "gib" => 1024f64.powi(3),
        "t" | "tib" => 1024f64.powi(4),
        "kb" => 1e3,
        "mb" => 1e6,
        "gb" => 1e9,
        "tb" => 1e12,
        _ => return Err(format!("unknown unit `{unit}` (use B, K/KiB, M/MiB, G/GiB, T/TiB, or KB, MB, GB, TB)")),
    };
    let bytes = value * scale;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("`{t}` is not a size between 1 byte and 16 EiB"));
    }
    Ok(bytes as u64)
}

fn err(name: &'static str, value: &str, why: impl Into<String>) -> TuningError {
    TuningError { name, value: value.to_string(), why: why.into() }
}

/// An on/off switch: `0`, `off`, `false`, `no`, or `1`, `on`, `true`, `yes`.
fn switch((name, v): (&'static str, String)) -> Result<bool, TuningError> {
    match v.trim().to_ascii_lowercase().as_str() {
        "0" | "off" | "false" | "no" => Ok(false),
        "1" | "on" | "true" | "yes" => Ok(true),
        _ => Err(err(name, &v, "expected 0 or 1 (off or on)")),
    }
}

/// A whole number within `range`.
fn number_in((name, v): (&'static str, String), range: std::ops::RangeInclusive<u32>) -> Result<u32, TuningError> {
    match v.trim().parse::<u32>() {
        Ok(n) if range.contains(&n) => Ok(n),
        _ => Err(err(name, &v, format!("expected a whole number from {} to {}", range.start(), range.end()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from(pairs: &[(&str, &str)]) -> Result<Tuning, TuningError> {
        Tuning::from_vars(|name| pairs.iter().find(|(n, _)| *n == name).map(|(_, v)| v.to_string()))
    }

    #[test]
    fn unset_and_empty_variables_keep_the_defaults() {
        assert_eq!(from(&[]).unwrap(), Tuning::default());
        assert_eq!(from(&[("TREELET_SPLITS", " "), ("TREELET_TREELETS", "")]).unwrap(), Tuning::default());
    }

    #[test]
    fn values_parse_into_their_fields() {
        let t = from(&[
            ("TREELET_SPLITS", "0.5"),
            ("TREELET_TREELETS", "2, 3,4"),
            ("TREELET_SORT_LOOK_BACK", "0"),
            ("TREELET_SORT_TILES", "large"),
            ("TREELET_MAX_MEMORY", "2GiB"),
            ("TREELET_PIPELINE_CACHE", "off"),
            ("TREELET_PROFILE_LEVELS", "empty"),
            ("TREELET_WIDE_COSTS", "1.5,2"),
            ("TREELET_HIERARCHY", "hploc"),
        ])
        .unwrap();
        assert_eq!(t.hierarchy, Some(Hierarchy::Hploc));
        assert_eq!(t.splits, Some(0.5));
        assert_eq!(t.treelets, Some((2, 3, 4)));
        assert!(!t.sort_look_back);
        assert_eq!(t.sort_tiles, Some(SortTiles::Large));
        assert_eq!(t.max_memory, Some(2 << 30));
        assert_eq!(t.pipeline_cache, PipelineCache::Off);
        assert_eq!(t.profile_levels, Some(ProfileLevels::WithEmptyLaunches));
        assert_eq!(t.wide_costs, Some((1.5, 2.0)));
    }

    #[test]
    fn a_bad_value_names_its_variable() {
        for (name, value) in [
            ("TREELET_SPLITS", "-1"),
            ("TREELET_SPLITS", "lots"),
            ("TREELET_TREELETS", "3,3"),
            ("TREELET_TREELETS", "3,3,0"),
            ("TREELET_TREELETS", "3,3,1025"),
            // Bounded as `--reinsert` is: 2^32 - 1 iterations never ended (a probe, 2026-12-02).
            ("TREELET_REINSERT", "4294967295"),
            ("TREELET_REINSERT", "65"),
            ("TREELET_SORT_LOOK_BACK", "maybe"),
            ("TREELET_SORT_TILES", "huge"),
            ("TREELET_MORTON_KEY_BITS", "65"),
            ("TREELET_HIERARCHY", "octree"),
            ("TREELET_MAX_MEMORY", "8 parsecs"),
            ("TREELET_WIDE_COSTS", "1"),
        ] {
            let e = from(&[(name, value)]).expect_err(value);
            assert_eq!(e.name, name);
            assert!(e.to_string().starts_with(&format!("{name}=")), "{e}");
        }
    }

    #[test]
    fn sizes_read_with_their_units() {
        assert_eq!(parse_bytes("1000000000"), Ok(1_000_000_000));
        assert_eq!(parse_bytes("1GB"), Ok(1_000_000_000));
        assert_eq!(parse_bytes("1 GiB"), Ok(1 << 30));
        assert_eq!(parse_bytes("512m"), Ok(512 << 20));
        assert_eq!(parse_bytes("1.5K"), Ok(1536));
        for bad in ["lots", "1XB", "0", "-5", "1e999", ""] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }
}
