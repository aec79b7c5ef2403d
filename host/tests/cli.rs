//! The `treelet` command as a user runs it: exit codes and messages.
use std::process::Command;

fn treelet(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_treelet")).args(args).output().expect("run treelet")
}

#[test]
fn cli_exits_nonzero_with_message() {
    let out = treelet(&["build", "--scene", "random:nope", "--device", "cpu"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("error:") && stderr.contains("random:nope"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn cpu_build_prints_valid_json() {
    let out = treelet(&["build", "--scene", "random:5000:3", "--device", "cpu", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
    assert_eq!(v["valid"], true);
    assert_eq!(v["primitives"], 5000);
    assert_eq!(v["nodes"], 9999);
    assert_eq!(v["device"], "cpu");
    assert_eq!(v["adapter"], "cpu");
    assert!(v["sah_cost"].as_f64().unwrap() > 0.0);
    for stage in ["bounds", "morton", "sort", "tree", "fit"] {
        assert!(v["ms"][stage].as_f64().is_some(), "stage {stage} missing");
    }
}

#[test]
fn empty_scene_builds_an_empty_tree() {
    let out = treelet(&["build", "--scene", "random:0", "--device", "cpu", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["nodes"], 0);
    assert_eq!(v["valid"], true);
}
