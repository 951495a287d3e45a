//! Body parameters are validated: every non-finite, zero or negative M, a, g, I_X, I_Z is a typed error
//! naming the field and carrying the value, and all bad fields are reported at once.

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use coin_log::model::{CoinParams, Inertia, ParamError};

const FIELDS: [&str; 5] = ["mass", "radius", "gravity", "inertia_x", "inertia_z"];
const BAD: [f64; 6] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0, -1.5];

/// Builds explicit-inertia parameters with `field` set to `value` and the others valid.
fn with_field(field: &str, value: f64) -> Result<CoinParams, Vec<ParamError>> {
    let mut v = [0.5, 2.0, 9.81, 0.35, 0.6];
    let i = FIELDS.iter().position(|f| *f == field).unwrap();
    v[i] = value;
    CoinParams::new(
        v[0],
        v[1],
        v[2],
        Inertia::Explicit {
            inertia_x: v[3],
            inertia_z: v[4],
        },
    )
}

fn names(errors: &[ParamError]) -> Vec<&'static str> {
    errors.iter().map(|e| e.name).collect()
}

#[test]
fn each_bad_value_of_each_field_is_an_error_naming_that_field() {
    for field in FIELDS {
        for bad in BAD {
            let errors = with_field(field, bad).unwrap_err();
            println!("{field} = {bad}: {errors:?} (expected exactly one error naming `{field}`)");
            assert_eq!(names(&errors), vec![field]);
            let value = errors[0].value;
            assert!(
                value.to_bits() == bad.to_bits() || (value.is_nan() && bad.is_nan()),
                "the error carries {value}, not the given {bad}"
            );
            let message = errors[0].to_string();
            assert!(
                message.contains(field) && message.contains("> 0"),
                "message `{message}` must name `{field}` and the allowed range"
            );
        }
    }
}

#[test]
fn all_bad_fields_are_reported_at_once() {
    let errors = CoinParams::new(
        f64::NAN,
        0.0,
        -9.81,
        Inertia::Explicit {
            inertia_x: f64::INFINITY,
            inertia_z: -0.1,
        },
    )
    .unwrap_err();
    println!("all five bad: {errors:?}");
    assert_eq!(names(&errors), FIELDS.to_vec());

    // With a shape, only the body's own fields can be bad; the derived inertias are not reported twice.
    let errors = CoinParams::new(-1.0, f64::NAN, 1.0, Inertia::ThinDisk).unwrap_err();
    println!("thin disk, bad mass and radius: {errors:?}");
    assert_eq!(names(&errors), vec!["mass", "radius"]);
}

#[test]
fn valid_parameters_are_accepted_with_the_shape_inertias_of_notes_section_2() {
    let (m, a) = (0.5, 2.0);
    let disk = CoinParams::new(m, a, 9.81, Inertia::ThinDisk).unwrap();
    let hoop = CoinParams::new(m, a, 9.81, Inertia::Hoop).unwrap();
    let ma2 = m * a * a;
    for (what, measured, expected) in [
        ("disk I_X", disk.inertia_x(), ma2 / 4.0),
        ("disk I_Z", disk.inertia_z(), ma2 / 2.0),
        ("hoop I_X", hoop.inertia_x(), ma2 / 2.0),
        ("hoop I_Z", hoop.inertia_z(), ma2),
        (
            "time unit sqrt(a/g)",
            disk.time_unit(),
            (a / 9.81_f64).sqrt(),
        ),
    ] {
        println!("{what}: measured {measured}, expected {expected}, tolerance 1 ulp");
        assert!((measured - expected).abs() <= f64::EPSILON * expected);
    }
    // Tiny and huge but finite positive values are valid.
    assert!(with_field("mass", f64::MIN_POSITIVE).is_ok());
    assert!(with_field("gravity", f64::MAX).is_ok());
}

/// A shape whose derived inertia M a²/4 overflows to infinity or underflows to zero is not a valid body,
/// even though M and a alone are finite and positive: the validated parameters promise finite, positive
/// inertias to every formula downstream.
#[test]
fn a_shape_whose_derived_inertia_overflows_or_underflows_is_rejected() {
    for (m, a) in [(1e300, 1e10), (1e-200, 1e-100)] {
        for shape in [Inertia::ThinDisk, Inertia::Hoop] {
            let result = CoinParams::new(m, a, 1.0, shape);
            println!(
                "M = {m:e}, a = {a:e}, {shape:?}: {result:?} (expected an error naming an inertia)"
            );
            let errors = result.unwrap_err();
            assert!(
                names(&errors).iter().all(|n| n.starts_with("inertia")),
                "{errors:?}"
            );
        }
    }
}
