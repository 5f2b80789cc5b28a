//! The JSON B-spline reader on arbitrary bytes: never a panic; a curve it accepts can be
//! evaluated across its domain without a panic, and serialises back to the same curve.
#![no_main]

use std::path::Path;

use batten::io;
use batten::{Curve, CurveDeriv};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(c) = io::parse_curve_json(data, Path::new("f.json")) {
        let (a, b) = c.domain();
        for k in 0..=8 {
            let t = a + (b - a) * f64::from(k) / 8.0;
            let _ = c.eval(t);
            let _ = c.derivatives(t);
        }
        let json = serde_json::to_string(&c).unwrap();
        let back = io::parse_curve_json(json.as_bytes(), Path::new("f.json")).unwrap();
        assert_eq!(back, c);
    }
});
