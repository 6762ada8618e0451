//! `drumroll cases`: the listing names every built-in fixture with its parameters, and
//! `cases show` prints the shipped file, which works as a user's own file once saved.

mod common;

use common::{drumroll, json_of, number};

fn stdout_of(args: &[&str]) -> String {
    let output = drumroll().args(args).output().expect("runs");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("utf-8")
}

#[test]
fn the_listing_names_every_fixture_file_with_its_key_parameters() {
    let listing = stdout_of(&["cases"]);
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures");
    for kind in ["cases", "cantilevers", "samples"] {
        for entry in std::fs::read_dir(format!("{root}/{kind}")).expect("fixtures") {
            let path = entry.expect("entry").path();
            let name = path
                .file_stem()
                .expect("stem")
                .to_string_lossy()
                .to_string();
            assert!(
                listing
                    .lines()
                    .any(|l| l.trim_start().starts_with(&format!("{name} "))),
                "{name} missing from:\n{listing}"
            );
        }
    }
    // Values straight from the fixture files: biolever k1 0.036 N/m, mica 60 GPa.
    assert!(
        listing.contains("k1 = 0.036 N/m, f1 = 9.3 kHz, Q1 = 1.2"),
        "{listing}"
    );
    assert!(listing.contains("E = 60 GPa"), "{listing}");
}

#[test]
fn show_prints_the_shipped_file_which_runs_as_a_user_file() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures");
    for (name, file) in [
        ("biolever-mica", "cases/biolever-mica.json"),
        ("maclever", "cantilevers/maclever.json"),
        ("purple-membrane", "samples/purple-membrane.json"),
    ] {
        let shown = stdout_of(&["cases", "show", name]);
        let shipped = std::fs::read_to_string(format!("{root}/{file}")).expect("fixture");
        assert_eq!(shown.trim_end(), shipped.trim_end(), "{name}");
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    let copy = directory.path().join("my-case.json");
    std::fs::write(&copy, stdout_of(&["cases", "show", "biolever-mica"])).expect("saved");
    let builtin = json_of(&["simulate", "--case", "biolever-mica", "--z", "12"]);
    let edited = json_of(&[
        "simulate",
        "--case",
        copy.to_str().expect("utf-8"),
        "--z",
        "12",
    ]);
    assert_eq!(number(&builtin, "phase_deg"), number(&edited, "phase_deg"));
    let output = drumroll()
        .args(["cases", "show", "no-such"])
        .output()
        .expect("runs");
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("no-such") && stderr.contains("biolever-mica"),
        "{stderr}"
    );
}
