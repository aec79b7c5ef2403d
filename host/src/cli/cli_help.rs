//! Checks of the command's help text: plain words a user reads, with no
//! rustdoc syntax or internal paths (the help comes from doc comments), and
//! `auto`'s descriptions held to what the code chooses.
use super::Cli;
use clap::{CommandFactory, ValueEnum};
use treelet::bvh::choice::{cheaper_builder, Work};
use treelet::bvh::layout::Layout;
use treelet::bvh::tree::{Accel, Builder};
use treelet::render::variant::PILOT_MIN_SPP;
use treelet::runtime::backend::DeviceClass;

/// Every (sub)command's long help, with its path (`treelet bench rays`).
fn every_help(command: &mut clap::Command, path: String, out: &mut Vec<(String, String)>) {
    out.push((path.clone(), command.render_long_help().to_string()));
    for sub in command.get_subcommands_mut() {
        let name = sub.get_name().to_string();
        every_help(sub, format!("{path} {name}"), out);
    }
}

#[test]
fn help_is_plain_words() {
    let mut helps = Vec::new();
    every_help(&mut Cli::command(), "treelet".to_string(), &mut helps);
    assert!(helps.len() > 15, "{} commands", helps.len());
    let mut bad = Vec::new();
    for (path, text) in &helps {
        for line in text.lines() {
            if ["`", "::", "crate::", "[`"].iter().any(|s| line.contains(s)) {
                bad.push(format!("{path}: {}", line.trim()));
            }
        }
    }
    assert!(bad.is_empty(), "help lines with rustdoc syntax or internal paths:\n{}", bad.join("\n"));
}

fn help_of<T: ValueEnum>(value: T) -> String {
    value.to_possible_value().and_then(|v| v.get_help().map(|h| h.to_string())).expect("a help text")
}

/// How `--layout auto`'s help names each class of device.
fn class_words(class: DeviceClass) -> &'static str {
    match class {
        DeviceClass::Gpu => "on GPUs",
        DeviceClass::CpuAdapter => "on CPU Vulkan adapters",
        DeviceClass::CpuRunner => "on the CPU runner",
    }
}

#[test]
fn layout_auto_help_says_what_resolve_picks() {
    let help = help_of(Layout::Auto);
    for class in [DeviceClass::Gpu, DeviceClass::CpuAdapter, DeviceClass::CpuRunner] {
        let at = help.find(class_words(class)).unwrap_or_else(|| panic!("{help:?} does not name {class:?}"));
        // The layout named last before the class is the one it gets.
        let named = Layout::ALL
            .iter()
            .filter_map(|l| help[..at].rfind(l.name()).map(|p| (p, *l)))
            .max_by_key(|&(p, _)| p)
            .map(|(_, l)| l);
        assert_eq!(named, Some(Layout::Auto.resolve(class)), "{class:?} in {help:?}");
    }
    assert!(help.contains(&format!("{PILOT_MIN_SPP} samples per pixel")), "{help:?}");
}

#[test]
fn accel_auto_help_names_the_builders_it_can_pick() {
    let help = help_of(Accel::Auto);
    assert!(help.contains("linear scan"), "{help:?}");
    let mut picked: Vec<(Builder, DeviceClass)> = Vec::new();
    for class in [DeviceClass::Gpu, DeviceClass::CpuAdapter, DeviceClass::CpuRunner] {
        for n in [1_000, 10_000, 100_000, 1_000_000, 10_000_000, 100_000_000] {
            for e in 10..44 {
                let b = cheaper_builder(class, n, Work::Paths(1 << e)).0;
                if !picked.contains(&(b, class)) {
                    picked.push((b, class));
                }
            }
        }
    }
    for b in [Builder::Lbvh, Builder::Hploc, Builder::Trbvh, Builder::Sweep, Builder::Reference] {
        let classes: Vec<DeviceClass> = picked.iter().filter(|p| p.0 == b).map(|p| p.1).collect();
        let named = help.contains(b.name());
        assert_eq!(named, !classes.is_empty(), "{} picked on {classes:?}; help {help:?}", b.name());
        if classes == [DeviceClass::Gpu] {
            assert!(help.contains(&format!("{} (GPUs only)", b.name())), "{help:?}");
        }
    }
}
