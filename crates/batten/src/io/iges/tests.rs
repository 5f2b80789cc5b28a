//! Tests of reading and writing IGES.

use super::*;

fn read(text: &str, pick: &Pick) -> Result<(Raw, Origin), String> {
    parse(text.as_bytes(), Path::new("c.igs"), pick).map_err(|e| e.to_string())
}

fn curve() -> BSplineCurve {
    let knots = KnotVector::try_new(vec![0., 0., 0., 0., 0.3, 1.0 / 3.0, 1., 1., 1., 1.]).unwrap();
    let ctrl = vec![
        Point::new(0.1, -1.0 / 3.0),
        Point::new(1e-300, 2.5),
        Point::new(3.0, 1e5 / 7.0),
        Point::new(-4.0, 0.0),
        Point::new(5.0, -2.0),
        Point::new(6.0, f64::MAX / 3.0),
    ];
    BSplineCurve::try_new(3, knots, ctrl, Some(vec![1.0, 0.5, 2.0, 1.0, 1.0, 0.75])).unwrap()
}

#[test]
fn reals_are_exact_with_a_point_and_d_exponent() {
    assert_eq!(real_str(0.1), "1.0D-1");
    assert_eq!(real_str(-2500.0), "-2.5D3");
    assert_eq!(real_str(0.0), "0.0D0");
    for x in [
        0.1,
        -1.0 / 3.0,
        1e-300,
        5e-324,
        f64::MAX,
        -0.0,
        123456789.125,
    ] {
        assert_eq!(real(&real_str(x)).unwrap().to_bits(), x.to_bits(), "{x}");
    }
    assert_eq!(real("1."), Some(1.0));
    assert_eq!(real(".5E1"), Some(5.0));
    assert_eq!(real("2d2"), Some(200.0));
}

#[test]
fn records_are_80_columns_and_the_curve_reads_back_bit_for_bit() {
    let c = curve();
    let origin = Origin {
        z: 7.5,
        layer: Some("3".into()),
        name: None,
    };
    let text = format_curve(&c, false, &origin);
    assert!(text.lines().all(|l| l.len() == 80), "{text}");
    let (raw, o) = read(&text, &Pick::default()).unwrap();
    let Raw::Curve(back) = raw else { panic!() };
    assert_eq!(back, c);
    assert_eq!(o.z, 7.5);
    assert_eq!(o.layer.as_deref(), Some("3"));
    assert_eq!(o.name.as_deref(), Some("1"));
    // Polynomial: no weights.
    let plain =
        BSplineCurve::try_new(3, c.knots().clone(), c.control_points().to_vec(), None).unwrap();
    let (raw, _) = read(
        &format_curve(&plain, false, &Origin::default()),
        &Pick::default(),
    )
    .unwrap();
    assert_eq!(raw_curve(raw), plain);
}

fn raw_curve(r: Raw) -> BSplineCurve {
    match r {
        Raw::Curve(c) => c,
        _ => panic!("not a curve"),
    }
}

#[test]
fn copious_data_round_trip_open_and_closed() {
    let pts: Vec<Point> = (0..40)
        .map(|i| Point::new(f64::from(i) / 7.0, (f64::from(i) * 0.3).sin()))
        .collect();
    for closed in [false, true] {
        let text = format_points(
            &pts,
            closed,
            &Origin {
                z: -1.0,
                ..Origin::default()
            },
        );
        let (raw, o) = read(&text, &Pick::default()).unwrap();
        let Raw::Points {
            points, closed: c, ..
        } = raw
        else {
            panic!()
        };
        assert_eq!(points, pts);
        assert_eq!(c, closed);
        assert_eq!(o.z, -1.0);
    }
}

/// A file in the style of other writers: delimiters defaulted, reals as `1.`, `E`
/// exponents, two entities, a 3-D polyline.
const TWO: &str = "\
Hand-made test file                                                     S      1
,,4Htest,5Hx.igs,4Htest,3H1.0,32,38,6,308,15,4Htest,1.,2,2HMM,1,1.,     G      1
15H20240101.000000,1.E-08,10.,,,11,0,15H20240101.000000;                G      2
     106       1       0       0       0       0       0       000000000D      1
     106       0       0       1      11                               0D      2
     106       2       0       0       5       0       0       000000000D      3
     106       0       0       2      12                               0D      4
106,1,4,0.,0.,0.,1.,0.,1.,1.,2.,1.5E0;                                 1P      1
106,2,4,0.,0.,0.,1.,0.,0.,1.,1.,1.,2.,1.5,                             3P      2
2.;                                                                    3P      3
S      1G      2D      4P      3                                        T      1
";

#[test]
fn other_writers_style_picking_and_3d_copious_data() {
    let e = read(TWO, &Pick::default()).unwrap_err();
    assert_eq!(
        e,
        "c.igs: 2 curve entities, pick one with --entity DE or --layer LEVEL: entity 106 form 11 at DE 1 (level 0), entity 106 form 12 at DE 3 (level 5)"
    );
    let (raw, o) = read(TWO, &Pick::default().with_entity(Some("1".into()))).unwrap();
    let Raw::Points { points, lines, .. } = raw else {
        panic!()
    };
    assert_eq!(points[3], Point::new(2.0, 1.5));
    assert_eq!(lines, vec![8; 4]);
    assert_eq!(o.z, 0.0);
    // Its z varies: a space curve.
    let (raw, _) = read(TWO, &Pick::default().with_layer(Some("5".into()))).unwrap();
    let Raw::Space { points, closed, .. } = raw else {
        panic!("not a space curve")
    };
    assert!(!closed);
    assert_eq!(points[1], [1.0, 0.0, 0.0]);
    assert_eq!(points[3], [2.0, 1.5, 2.0]);
    let e = read(TWO, &Pick::default().with_entity(Some("7".into()))).unwrap_err();
    assert!(
        e.starts_with("c.igs: no curve entity at directory entry 7 (curve entities: entity 106"),
        "{e}"
    );
}

#[test]
fn malformed_files_name_the_line() {
    let e = read("hello\n", &Pick::default()).unwrap_err();
    assert_eq!(
        e,
        "c.igs:1: record too short for a section letter in column 73 (not a fixed-form IGES file?)"
    );
    let bad = TWO.replace(
        "106,1,4,0.,0.,0.,1.,0.,1.,1.,2.,1.5E0;",
        "106,1,4,0.,0.,0.,1.,0.,1.,1.,2.,x.5E0;",
    );
    let e = read(&bad, &Pick::default().with_entity(Some("1".into()))).unwrap_err();
    assert_eq!(
        e,
        "c.igs:8: entity 106 form 11 at DE 1 (level 0): parameter 11 'x.5E0' is not a finite real"
    );
    let bad = TWO.replace(
        "106,1,4,0.,0.,0.,1.,0.,1.,1.,2.,1.5E0;",
        "106,1,5,0.,0.,0.,1.,0.,1.,1.,2.,1.5E0;",
    );
    let e = read(&bad, &Pick::default().with_entity(Some("1".into()))).unwrap_err();
    assert_eq!(
        e,
        "c.igs:8: entity 106 form 11 at DE 1 (level 0): 12 parameters, more expected"
    );
    let bad = TWO.replace(
        "     106       1       0       0       0       0       0       000000000D      1",
        "     106      99       0       0       0       0       0       000000000D      1",
    );
    let e = read(&bad, &Pick::default().with_entity(Some("1".into()))).unwrap_err();
    assert!(
        e.starts_with(
            "c.igs:4: entity 106 form 11 at DE 1 (level 0): its parameter data pointer 99"
        ),
        "{e}"
    );
    let e = read(
        &TWO.replace(
            ";                                 1P",
            ",                                 1P",
        ),
        &Pick::default().with_entity(Some("1".into())),
    )
    .unwrap_err();
    assert!(e.ends_with("the record delimiter is missing"), "{e}");
}
