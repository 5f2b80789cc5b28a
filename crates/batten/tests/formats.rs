//! DXF, IGES and SVG: files from other writers (Open CASCADE's IGES writer, made by
//! `fixtures/make_iges_fixtures.py`) and write-then-read round trips through the public API.

#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};

use batten::Point;
use batten::io::{self, Format, Origin, Pick, ReadOptions, Source};
use batten::spline::{BSplineCurve, KnotVector};
use proptest::prelude::*;

/// The relative rounding of a real printed with 9 significant digits, as OCCT's IGES writer
/// prints them.
const OCCT_DIGITS: f64 = 5e-9;

/// The dxf crate writes 12 decimal places: a coordinate reads back within half a unit of
/// the 12th place, plus the rounding of the decimal to the nearest double.
fn dxf_close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 5e-13 + f64::EPSILON * b.abs()
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/iges")
        .join(name)
}

fn expected() -> serde_json::Value {
    let text = std::fs::read_to_string(fixture("expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn read_curve(path: &Path) -> (BSplineCurve, Origin) {
    let input = io::read_input(path, None, &ReadOptions::default(), &Pick::default()).unwrap();
    match input.source {
        Source::Curve(c) => (c, input.origin),
        other => panic!("not a B-spline: {other:?}"),
    }
}

#[test]
fn occt_iges_files_read_as_the_curves_occt_was_given() {
    let exp = expected();
    for name in ["occt_bspline.igs", "occt_nurbs.igs", "occt_z5.igs"] {
        let e = &exp[name];
        let (c, origin) = read_curve(&fixture(name));
        assert_eq!(c.degree() as u64, e["degree"].as_u64().unwrap(), "{name}");
        let knots: Vec<f64> = e["knots"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(c.knots().as_slice(), &knots[..], "{name}");
        let ctrl: Vec<Point> = e["control_points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| Point::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect();
        // OCCT prints reals with 9 significant digits (`0.707106781`).
        for (a, b) in c.control_points().iter().zip(&ctrl) {
            assert!(
                a.distance(*b) <= OCCT_DIGITS * b.x.abs().max(b.y.abs()),
                "{name}: {a:?} vs {b:?}"
            );
        }
        match e["weights"].as_array() {
            None => assert!(c.weights().is_none(), "{name}"),
            Some(w) => {
                for (a, b) in c.weights().unwrap().iter().zip(w) {
                    let b = b.as_f64().unwrap();
                    assert!((a - b).abs() <= OCCT_DIGITS * b.abs(), "{name}: {a} vs {b}");
                }
            }
        }
        assert_eq!(origin.z, e["z"][0].as_f64().unwrap(), "{name}");
    }
}

#[test]
fn occt_space_bspline_is_refused_in_one_line() {
    let e = io::read_input(
        &fixture("occt_space.igs"),
        None,
        &ReadOptions::default(),
        &Pick::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("occt_space.igs:"), "{e}");
    assert!(e.contains("a 3-D B-spline is not taken"), "{e}");
    assert!(!e.contains('\n'));
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e6..1e6f64,
        any::<f64>().prop_filter("finite", |x| x.is_finite()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// IGES and SVG written by batten read back bit for bit (IGES: any finite value; SVG:
    /// the Bézier points of a curve whose knots are already of full multiplicity).
    #[test]
    fn iges_and_svg_round_trips_are_bit_exact(
        raw in proptest::collection::vec((finite(), finite()), 4..12),
        z in -1e3..1e3f64,
    ) {
        let n = 3 * ((raw.len() - 1) / 3) + 1;
        let ctrl: Vec<Point> = raw[..n].iter().map(|&(x, y)| Point::new(x, y)).collect();
        let spans = (n - 1) / 3;
        let mut knots = vec![0.0; 4];
        for i in 1..spans {
            knots.extend([i as f64; 3]);
        }
        knots.extend([spans as f64; 4]);
        let c = BSplineCurve::try_new(3, KnotVector::try_new(knots).unwrap(), ctrl, None).unwrap();
        let mut origin = Origin::default();
        origin.z = z;
        for format in [Format::Iges, Format::Svg] {
            let bytes = io::format_curve(format, Path::new("o"), &c, false, &origin).unwrap();
            let back = io::parse_input(&bytes, format, Path::new("o"), &ReadOptions::default(), &Pick::default()).unwrap();
            let Source::Curve(b) = back.source else { panic!("points") };
            prop_assert_eq!(b.control_points().len(), c.control_points().len());
            for (p, q) in b.control_points().iter().zip(c.control_points()) {
                prop_assert_eq!((p.x.to_bits(), p.y.to_bits()), (q.x.to_bits(), q.y.to_bits()));
            }
            if format == Format::Iges {
                prop_assert_eq!(&b, &c);
                prop_assert_eq!(back.origin.z.to_bits(), z.to_bits());
            }
        }
    }

    /// Points written as IGES copious data read back bit for bit; as DXF, within the 12
    /// decimals the dxf crate writes.
    #[test]
    fn point_round_trips(
        raw in proptest::collection::vec((-1e3..1e3f64, -1e3..1e3f64), 4..30),
        closed in any::<bool>(),
    ) {
        let mut pts: Vec<Point> = raw.iter().map(|&(x, y)| Point::new(x, y)).collect();
        pts.dedup();
        prop_assume!(pts.len() >= 4 && pts.first() != pts.last());
        for format in [Format::Iges, Format::Dxf] {
            let bytes = io::format_points(format, Path::new("o"), &pts, closed, None, &Origin::default()).unwrap();
            let back = io::parse_input(&bytes, format, Path::new("o"), &ReadOptions::default(), &Pick::default()).unwrap();
            let Source::Points(d) = back.source else { panic!("curve") };
            prop_assert_eq!(d.seq.is_closed(), closed);
            prop_assert_eq!(d.seq.len(), pts.len());
            for (p, q) in d.seq.points().iter().zip(&pts) {
                if format == Format::Iges {
                    prop_assert_eq!((p.x.to_bits(), p.y.to_bits()), (q.x.to_bits(), q.y.to_bits()));
                } else {
                    prop_assert!(dxf_close(p.x, q.x) && dxf_close(p.y, q.y), "{:?} vs {:?}", p, q);
                }
            }
        }
    }
}

/// A valid file of each format, to mutate.
fn samples() -> Vec<(Format, Vec<u8>)> {
    let pts: Vec<Point> = (0..8)
        .map(|i| Point::new(f64::from(i), f64::from(i * i % 5)))
        .collect();
    let c = BSplineCurve::try_new(
        3,
        KnotVector::try_new(vec![0., 0., 0., 0., 0.5, 1., 1., 1., 1.]).unwrap(),
        pts[..5].to_vec(),
        Some(vec![1.0, 0.5, 2.0, 1.0, 1.0]),
    )
    .unwrap();
    let o = Origin::default();
    let p = Path::new("o");
    let mut v = Vec::new();
    for f in [Format::Iges, Format::Svg, Format::Dxf] {
        v.push((f, io::format_points(f, p, &pts, false, None, &o).unwrap()));
    }
    v.push((
        Format::Iges,
        io::format_curve(Format::Iges, p, &c, false, &o).unwrap(),
    ));
    v.push((
        Format::Dxf,
        io::format_curve(Format::Dxf, p, &c, false, &o).unwrap(),
    ));
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Damaged files are an error or a curve, never a panic: bytes overwritten, cut off or
    /// spliced into a valid file of each format.
    #[test]
    fn damaged_files_never_panic(
        which in 0usize..5,
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
        truncate in any::<bool>(),
    ) {
        let (format, mut bytes) = samples().swap_remove(which);
        for (at, b) in edits {
            let i = at.index(bytes.len());
            // Mostly characters the formats use, so the parsers get past their first check.
            bytes[i] = match b % 4 {
                0 => b"0123456789"[usize::from(b) % 10],
                1 => b",;.-+ED\n H"[usize::from(b) % 10],
                _ => b,
            };
        }
        if truncate {
            bytes.truncate(cut.index(bytes.len() + 1));
        }
        let r = io::parse_input(&bytes, format, Path::new("o"), &ReadOptions::default(), &Pick::default());
        if let Err(e) = r {
            let m = e.to_string();
            prop_assert!(m.starts_with("o"), "{}", m);
            prop_assert!(!m.contains('\n'), "{}", m);
        }
    }
}

fn dxf_fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/dxf")
        .join(name)
}

fn pairs(v: &serde_json::Value) -> Vec<Point> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| Point::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Every entity of a DXF file written by ezdxf (`fixtures/make_dxf_fixtures.py`), picked by
/// its handle, reads as what ezdxf was given, bit for bit; the 3-D polyline whose z varies
/// (marked `refused` by the fixture script, from before space curves) reads as a space curve.
#[test]
fn ezdxf_entities_read_as_ezdxf_was_given() {
    let text = std::fs::read_to_string(dxf_fixture("expected.json")).unwrap();
    let exp: serde_json::Value = serde_json::from_str(&text).unwrap();
    let path = dxf_fixture("ezdxf_r2010.dxf");
    let entities = exp["entities"].as_object().unwrap();
    assert_eq!(entities.len(), 6);
    for (handle, e) in entities {
        let pick = Pick::default().with_entity(Some(handle.clone()));
        let r = io::read_input(&path, None, &ReadOptions::default(), &pick);
        if e.get("refused").is_some() {
            let input = r.unwrap();
            assert_eq!(input.origin.layer.as_deref(), Some("SPACE"));
            let Source::Space(d) = input.source else {
                panic!("{handle}: not a space curve")
            };
            assert_eq!(d.seq.len(), 12);
            for (k, p) in d.seq.points().iter().enumerate() {
                assert!((p[2] - 0.1 * k as f64).abs() < 1e-12, "{handle}: {p:?}");
            }
            continue;
        }
        let input = r.unwrap();
        assert_eq!(input.origin.name.as_deref(), Some(handle.as_str()));
        assert_eq!(input.origin.layer.as_deref(), e["layer"].as_str());
        assert_eq!(input.origin.z, e["z"].as_f64().unwrap(), "{handle}");
        match input.source {
            Source::Points(d) => {
                assert_eq!(d.seq.points(), &pairs(&e["points"])[..], "{handle}");
                assert_eq!(
                    d.seq.is_closed(),
                    e["closed"].as_bool().unwrap(),
                    "{handle}"
                );
            }
            Source::Curve(c) => {
                assert_eq!(c.degree() as u64, e["degree"].as_u64().unwrap());
                assert_eq!(c.knots().as_slice(), &floats(&e["knots"])[..]);
                assert_eq!(c.control_points(), &pairs(&e["control_points"])[..]);
                assert_eq!(c.weights().unwrap(), &floats(&e["weights"])[..]);
            }
            other => panic!("{handle}: a space curve: {other:?}"),
        }
    }
}
