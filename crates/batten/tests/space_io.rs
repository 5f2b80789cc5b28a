//! Space curves in text and JSON: read as `x, y, z`, validated as planar points are (the same
//! messages, naming the line), written back bit for bit; a planar reader refuses them in one
//! line.
#![allow(clippy::unwrap_used)]

use std::path::Path;

use batten::io::{self, Format, Origin, Pick, ReadOptions, Source, SpaceData};

fn read(text: &str, format: Format) -> Result<Source, String> {
    let name = match format {
        Format::Json => "c.json",
        Format::Iges => "c.igs",
        _ => "c.csv",
    };
    io::parse_input(
        text.as_bytes(),
        format,
        Path::new(name),
        &ReadOptions::default(),
        &Pick::default(),
    )
    .map(|i| i.source)
    .map_err(|e| e.to_string())
}

fn space(text: &str, format: Format) -> SpaceData {
    match read(text, format) {
        Ok(Source::Space(d)) => d,
        other => panic!("not a space curve: {other:?}"),
    }
}

fn err(text: &str, format: Format) -> String {
    match read(text, format) {
        Err(e) => e,
        Ok(s) => panic!("expected an error, got {s:?}"),
    }
}

const HELIX: &str = "x,y,z\n1,0,0\n0.5,0.8,0.1\n-0.4,0.9,0.2\n-1,0.1,0.3\n-0.6,-0.8,0.4\n";

#[test]
fn three_columns_are_a_space_curve() {
    let d = space(HELIX, Format::Text);
    assert_eq!(d.seq.len(), 5);
    assert_eq!(d.seq.points()[1], [0.5, 0.8, 0.1]);
    assert_eq!(d.lines, vec![2, 3, 4, 5, 6]);
    assert!(!d.seq.is_closed());
    // Without a header, the first row decides; any separator the planar reader takes.
    let d = space(
        "1 0 0\n0.5;0.8;0.1\n-0.4\t0.9\t0.2\n-1,0.1,0.3\n",
        Format::Text,
    );
    assert_eq!(d.seq.points()[3], [-1.0, 0.1, 0.3]);
    // Two columns stay planar.
    assert!(matches!(
        read("0,0\n1,1\n2,0\n3,1\n", Format::Text),
        Ok(Source::Points(_))
    ));
}

#[test]
fn rows_must_match_the_first() {
    assert_eq!(
        err("1,0,0\n0.5,0.8\n", Format::Text),
        "c.csv:2: expected 3 fields (x, y, z), found 2"
    );
    assert_eq!(
        err("0,0\n1,1,1\n", Format::Text),
        "c.csv:2: expected 2 fields (x, y), found 3"
    );
    assert_eq!(
        err("x,y,z\n1,2\n", Format::Text),
        "c.csv:2: expected 3 fields (x, y, z), found 2"
    );
    assert_eq!(
        err("1,2,3,4\n", Format::Text),
        "c.csv:1: expected 2 fields (x, y) or 3 (x, y, z), found 4"
    );
    assert_eq!(
        err("1,0,0\n2,0,x\n", Format::Text),
        "c.csv:2: field 3 'x' is not a number"
    );
}

#[test]
fn space_points_are_validated_as_planar_ones() {
    assert_eq!(
        err("1,0,0\n1,0,0\n2,0,1\n3,1,1\n", Format::Text),
        "c.csv:2: point duplicates the previous one (line 1)"
    );
    assert_eq!(
        err("1,0,0\n2,0,1e301\n2,0,1\n3,1,1\n", Format::Text),
        "c.csv:2: coordinate 1e301 is beyond ±1e300, the largest magnitude batten takes \
         (rescale the data)"
    );
    assert_eq!(
        err("1,0,0\n2,0,1\n3,1,1\n", Format::Text),
        "c.csv: 3 points, at least 4 needed"
    );
    // Points apart in z alone are distinct.
    let d = space("0,0,0\n0,0,1\n1,0,1\n1,1,1\n", Format::Text);
    assert_eq!(d.seq.len(), 4);
}

#[test]
fn json_points_with_three_coordinates() {
    let j =
        "{\"points\": [\n[0, 0, 0],\n[1, 0, 0.5],\n[1, 1, 1],\n[0, 1, 1.5]\n], \"closed\": true}";
    let d = space(j, Format::Json);
    assert!(d.seq.is_closed());
    assert_eq!(d.lines, vec![2, 3, 4, 5]);
    let mixed = "{\"points\": [\n[0, 0, 0],\n[1, 0],\n[1, 1, 1],\n[0, 1, 1.5]\n]}";
    assert_eq!(
        err(mixed, Format::Json),
        "c.json:3: expected 3 fields (x, y, z), as the first point, found 2"
    );
    let tangents = "{\"points\": [[0, 0, 0], [1, 0, 0.5], [1, 1, 1], [0, 1, 1.5]], \
                    \"tangents\": [[1, 0], [1, 0], [1, 0], [1, 0]]}";
    assert_eq!(
        err(tangents, Format::Json),
        "c.json: tangents are taken with planar points only, not with [x, y, z] points"
    );
}

#[test]
fn a_planar_reader_refuses_a_space_curve_in_one_line() {
    let e = io::parse_points(
        HELIX.as_bytes(),
        Format::Text,
        Path::new("c.csv"),
        &ReadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "c.csv: the file holds a 3-D curve (x, y, z points), not a planar one"
    );
}

#[test]
fn written_space_points_read_back_bit_for_bit() {
    let pts: Vec<[f64; 3]> = (0..40)
        .map(|i| {
            let t = f64::from(i) * 0.37;
            [t.cos() * 1e-7, t.sin() * 3.3e5, 0.1 * t + 1.0 / 3.0]
        })
        .collect();
    for (format, name) in [(Format::Text, "o.csv"), (Format::Json, "o.json")] {
        for closed in [false, true] {
            let bytes =
                io::format_space_points(format, Path::new(name), &pts, closed, &Origin::default())
                    .unwrap();
            let text = String::from_utf8(bytes).unwrap();
            let mut back = space(&text, format);
            if format == Format::Text {
                // A text file cannot say it is closed.
                assert!(!back.seq.is_closed());
            } else {
                assert_eq!(back.seq.is_closed(), closed);
            }
            assert_eq!(std::mem::take(&mut back.lines).len(), pts.len());
            assert_eq!(back.seq.points(), &pts[..], "{name}");
        }
    }
    let e = io::format_space_points(
        Format::Svg,
        Path::new("o.svg"),
        &pts,
        false,
        &Origin::default(),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "o.svg: a 3-D curve is written as .csv, .txt, .json, .dxf or .igs"
    );
    // IGES copious data (106 form 12) reads back bit for bit, closed when it returns to its
    // start.
    for closed in [false, true] {
        let bytes = io::format_space_points(
            Format::Iges,
            Path::new("o.igs"),
            &pts,
            closed,
            &Origin::default(),
        )
        .unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let back = space(&text, Format::Iges);
        assert_eq!(back.seq.is_closed(), closed);
        assert_eq!(back.seq.points(), &pts[..]);
    }
    let mut bad = pts.clone();
    bad[3][2] = f64::NAN;
    assert!(
        io::format_space_points(
            Format::Text,
            Path::new("o.csv"),
            &bad,
            false,
            &Origin::default()
        )
        .is_err()
    );
}

#[test]
fn a_dxf_3d_polyline_is_a_space_curve_and_is_written_as_one() {
    let pts: Vec<[f64; 3]> = (0..30)
        .map(|i| {
            let t = f64::from(i) * 0.3;
            [t.cos(), t.sin(), 0.25 * t]
        })
        .collect();
    let origin = Origin::default();
    for closed in [false, true] {
        let bytes = io::format_space_points(Format::Dxf, Path::new("o.dxf"), &pts, closed, &origin)
            .unwrap();
        let back = io::parse_input(
            &bytes,
            Format::Dxf,
            Path::new("o.dxf"),
            &ReadOptions::default(),
            &Pick::default(),
        )
        .unwrap();
        let Source::Space(d) = back.source else {
            panic!("not a space curve: {:?}", back.source)
        };
        assert_eq!(d.seq.is_closed(), closed);
        assert_eq!(d.seq.len(), pts.len());
        // The dxf crate writes 12 decimal places.
        for (a, b) in d.seq.points().iter().zip(&pts) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() <= 5e-13, "{a:?} {b:?}");
            }
        }
        // The drawing written back with new points keeps the entity and takes x, y and z.
        let mut drawing = io::DxfDrawing::parse(&bytes, Path::new("o.dxf")).unwrap();
        let curves = drawing.curves(&ReadOptions::default());
        let handle = curves[0].origin.name.clone().unwrap();
        let moved: Vec<[f64; 3]> = pts.iter().map(|p| [p[0], p[1], p[2] + 0.5]).collect();
        drawing
            .replace(&handle, io::DxfGeometry::Space(&moved))
            .unwrap();
        let again = io::DxfDrawing::parse(&drawing.to_bytes().unwrap(), Path::new("o.dxf"))
            .unwrap()
            .curves(&ReadOptions::default());
        let Ok(Source::Space(d)) = &again[0].source else {
            panic!("not a space curve")
        };
        assert!((d.seq.points()[7][2] - moved[7][2]).abs() <= 5e-13);
    }
}
