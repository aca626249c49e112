//! `rsmc --resume` on hostile checkpoints (issue 19, item 5): every field is
//! validated; a bad one gives exit 2 naming the field, and the files are left as they
//! were. Runs the real binary under a time cap (a zero generator state used to hang).

use serde_json::{json, Value};

mod hostile;
use hostile::{fails_naming, run_capped};

/// Edits the checkpoint of a fresh short run with `edit`, resumes, and expects a
/// clean failure naming `field`, with the checkpoint and series untouched.
fn resume_fails(edit: impl Fn(&mut Value), field: &str) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = run_capped(
        d,
        &["rsmc", "--steps", "2000", "--out", "r", "--json"],
        2048,
        60,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cp_path = d.join("r/checkpoint.json");
    // The generator's 128-bit state does not fit a JSON `Value` number: it stands
    // aside as a placeholder while the test edits the rest.
    let raw = std::fs::read_to_string(&cp_path).unwrap();
    let at = raw.find("\"state\":").unwrap() + "\"state\":".len();
    let end = at + raw[at..].find('}').unwrap();
    let state = raw[at..end].to_owned();
    let held = format!("{}\"STATE\"{}", &raw[..at], &raw[end..]);
    let mut cp: Value = serde_json::from_str(&held).unwrap();
    edit(&mut cp);
    let text = serde_json::to_string(&cp)
        .unwrap()
        .replace("\"STATE\"", &state);
    std::fs::write(&cp_path, &text).unwrap();
    let csv = std::fs::read(d.join("r/series.csv")).unwrap();
    let out = run_capped(
        d,
        &[
            "rsmc", "--steps", "4000", "--out", "r", "--resume", "--json",
        ],
        2048,
        20,
    );
    let err = fails_naming(&out, &[field]);
    assert!(err.contains("checkpoint.json"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&cp_path).unwrap(),
        text,
        "{field}: checkpoint changed"
    );
    assert_eq!(std::fs::read(d.join("r/series.csv")).unwrap(), csv);
}

#[test]
fn sample_every_zero_is_named() {
    resume_fails(|c| c["sample_every"] = json!(0), "sample_every");
}

#[test]
fn a_degenerate_generator_state_is_named() {
    // Zero made the bounded draw loop forever; any even state is one the generator
    // never reaches (it keeps its state odd).
    resume_fails(|c| c["chain"]["rng"]["state"] = json!(0), "rng.state");
    resume_fails(|c| c["chain"]["rng"]["state"] = json!(2), "rng.state");
}

#[test]
fn contradictory_counters_are_named() {
    resume_fails(
        |c| c["chain"]["counters"]["accepted"] = json!(1u64 << 40),
        "counters",
    );
    resume_fails(
        |c| {
            let a = c["chain"]["counters"]["accepted"].as_u64().unwrap();
            c["chain"]["counters"]["grown"] = json!(a + 1);
        },
        "counters.grown",
    );
    resume_fails(|c| c["chain"]["counters"]["illegal"] = json!(0), "counters");
}

#[test]
fn base_counters_beyond_the_chain_are_named() {
    resume_fails(|c| c["base_steps"] = json!(1u64 << 40), "base_steps");
    resume_fails(|c| c["base_accepted"] = json!(1u64 << 40), "base_accepted");
}

#[test]
fn bad_format_params_and_voxels_are_named() {
    resume_fails(|c| c["chain"]["format"] = json!(99), "format");
    resume_fails(|c| c["chain"]["params"]["max_area"] = json!(3), "max_area");
    // A surface already larger than its cap.
    resume_fails(|c| c["chain"]["params"]["max_area"] = json!(6), "max_area");
    resume_fails(|c| c["chain"]["voxels"] = json!([]), "voxels");
    resume_fails(
        |c| c["chain"]["voxels"] = json!([[i64::MAX, 0, 0]]),
        "voxels",
    );
}
