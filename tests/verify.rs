//! `coin-log verify` on good recordings and on negative controls: each tampered file must fail the right
//! check, by id, with the measured number in the report.
#![allow(clippy::unwrap_used)]

mod common_verify;

use coin_log::verify::{verify_file, CheckId, FileReport, Options, Status};
use common_verify::*;

fn show(r: &FileReport) -> String {
    r.checks
        .iter()
        .map(|c| {
            format!(
                "{:<12} {:<5} value {:?} tol {:?}  {}",
                c.id.as_str(),
                c.status.to_string(),
                c.value,
                c.tolerance,
                c.reason
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn status(r: &FileReport, id: CheckId) -> Status {
    r.check(id).unwrap().status
}

#[test]
fn a_recorded_wobble_passes_every_check_that_runs() {
    let (_dir, path) = recorded(&wobble(), "wobble.mcap");
    let r = verify_file(&path, &Options::default());
    println!("{}", show(&r));
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    for id in [
        CheckId::Integrity,
        CheckId::Energy,
        CheckId::Constraint,
        CheckId::Consistency,
        CheckId::Validity,
    ] {
        assert_eq!(status(&r, id), Status::Pass, "{id}\n{}", show(&r));
    }
    assert_eq!(status(&r, CheckId::Steady), Status::Skip);
}

#[test]
fn a_recorded_steady_circle_passes_the_steady_check() {
    let (_dir, path) = recorded(&steady_circle(), "circle.mcap");
    let r = verify_file(&path, &Options::default());
    println!("{}", show(&r));
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    assert_eq!(status(&r, CheckId::Steady), Status::Pass);
}
