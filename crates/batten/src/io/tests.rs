//! Tests of reading, validating and writing point lists and curves.

use super::*;
use std::fs;
use std::path::PathBuf;

use crate::geom::Point;

fn parse(text: &str, options: &ReadOptions) -> Result<PointData, IoError> {
    parse_points(
        text.as_bytes(),
        Format::Text,
        Path::new("data.csv"),
        options,
    )
}

fn msg(text: &str) -> String {
    match parse(text, &ReadOptions::default()) {
        Ok(_) => panic!("expected an error for {text:?}"),
        Err(e) => e.to_string(),
    }
}

fn tempdir() -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static DIRS: AtomicUsize = AtomicUsize::new(0);
    let n = DIRS.fetch_add(1, Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("batten-io-test-{}-{n}", std::process::id()));
    fs::create_dir_all(&d).unwrap();
    d
}

const SQUARE: &str = "x,y\n0,0\n1,0\n1,1\n0,1\n";

#[test]
fn format_from_extension() {
    assert_eq!(Format::from_path(Path::new("a.csv")).unwrap(), Format::Text);
    assert_eq!(Format::from_path(Path::new("a.TXT")).unwrap(), Format::Text);
    assert_eq!(
        Format::from_path(Path::new("d/a.Json")).unwrap(),
        Format::Json
    );
    for bad in ["a.dat", "a", "a.csv.gz", ".csv"] {
        let e = Format::from_path(Path::new(bad)).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{bad}: unknown file format (use a .csv, .txt, .json, .dxf, .igs/.iges or .svg file name)"
            )
        );
    }
}

#[test]
fn validation_errors_name_lines() {
    assert_eq!(msg(""), "data.csv: no points");
    assert_eq!(msg("# nothing\nx,y\n\n"), "data.csv: no points");
    assert_eq!(
        msg("x,y\n0,0\n1,1\n2,0\n"),
        "data.csv: 3 points, at least 4 needed"
    );
    assert_eq!(
        msg("x,y\n0,0\n1,1\n2,0\n3,1\n4,0\n# c\n\n4,0\n"),
        "data.csv:9: point duplicates the previous one (line 6)"
    );
    assert_eq!(
        msg("0,0\n1,1\n2,0\n3,1\n4,0\n5,1\n6,0\n7,1\n8,1\n8,1\n"),
        "data.csv:10: point duplicates the previous one (line 9)"
    );
    // A repeated first point is fine for an open curve, not for a closed one.
    let ring = "x,y\n0,0\n1,0\n1,1\n0,1\n0,0\n";
    assert!(parse(ring, &ReadOptions::default()).is_ok());
    let e = parse(ring, &ReadOptions::default().with_closed(true))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "data.csv:6: closed curve repeats its first point (line 2); leave the repeated point out"
    );
}

#[test]
fn closed_from_options_or_json() {
    let d = parse(SQUARE, &ReadOptions::default()).unwrap();
    assert!(!d.seq.is_closed());
    assert_eq!(d.lines, vec![2, 3, 4, 5]);
    let d = parse(SQUARE, &ReadOptions::default().with_closed(true)).unwrap();
    assert!(d.seq.is_closed());
    let j = br#"{"points": [[0,0],[1,0],[1,1],[0,1]], "closed": true}"#;
    let d = parse_points(j, Format::Json, Path::new("c.json"), &ReadOptions::DEFAULT).unwrap();
    assert!(d.seq.is_closed());
}

#[test]
fn json_validation_errors_name_lines() {
    let j = "{\"points\": [\n[0, 0],\n[1, 0],\n[1, 0],\n[2, 1]\n]}";
    let e = parse_points(
        j.as_bytes(),
        Format::Json,
        Path::new("d.json"),
        &ReadOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(e, "d.json:4: point duplicates the previous one (line 3)");
    let j = "{\"points\": [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]],\n \"closed\": true}";
    let e = parse_points(
        j.as_bytes(),
        Format::Json,
        Path::new("d.json"),
        &ReadOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "d.json:1: closed curve repeats its first point (line 1); leave the repeated point out"
    );
    let j = "{\"points\": [[0, 0], [1, 0], [1, 1], [0, 1]],\n \"tangents\": [[1, 0]]}";
    let e = parse_points(
        j.as_bytes(),
        Format::Json,
        Path::new("d.json"),
        &ReadOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(e, "d.json: 1 tangent for 4 points");
    let e = parse_points(
        b"{\"points\": []}",
        Format::Json,
        Path::new("d.json"),
        &ReadOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(e, "d.json: no points");
}

#[test]
fn write_read_round_trip_both_formats() {
    let dir = tempdir();
    let pts = vec![
        Point::new(-0.0, 1e-300),
        Point::new(1e300, 5e-324),
        Point::new(0.1, -1.0 / 3.0),
        Point::new(f64::MIN_POSITIVE / 3.0, -MAX_COORDINATE),
        Point::new(std::f64::consts::PI, -1e-7),
    ];
    let tangents = vec![Vec2::new(0.6, 0.8); 5];
    for name in ["p.csv", "p.txt", "p.json"] {
        let path = dir.join(name);
        write_points(&path, &pts, false, Some(&tangents)).unwrap();
        let back = read_points(&path, &ReadOptions::DEFAULT).unwrap();
        assert_eq!(back.seq.len(), pts.len());
        for (a, b) in pts.iter().zip(back.seq.points()) {
            assert_eq!(a.x.to_bits(), b.x.to_bits(), "{name}");
            assert_eq!(a.y.to_bits(), b.y.to_bits(), "{name}");
        }
        let want_tangents = name.ends_with(".json").then(|| tangents.clone());
        assert_eq!(back.tangents, want_tangents);
    }
    let text = fs::read_to_string(dir.join("p.csv")).unwrap();
    assert!(text.starts_with("x,y\n-0,1e-300\n1e300,5e-324\n"), "{text}");
    // Closed, the last point must not nearly repeat the first (relative to the extent).
    let path = dir.join("closed.json");
    // Closed, these points would be refused: the closing chord, π, is 10⁻³⁰⁸ of the size.
    let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(x, y)| Point::new(x, y));
    write_points(&path, &square, true, None).unwrap();
    assert!(
        read_points(&path, &ReadOptions::DEFAULT)
            .unwrap()
            .seq
            .is_closed()
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_rejects_non_finite_and_unknown_format() {
    let dir = tempdir();
    let mut pts = vec![Point::new(0.0, 0.0); 4];
    pts[2].y = f64::NAN;
    let path = dir.join("o.csv");
    let e = write_points(&path, &pts, false, None)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        format!(
            "{}: cannot write point 2: NaN or infinite value",
            path.display()
        )
    );
    assert!(!path.exists());
    let path = dir.join("o.xyz");
    assert!(matches!(
        write_points(&path, &[], false, None),
        Err(IoError::UnknownFormat { .. })
    ));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn atomic_write_replaces_and_leaves_no_temporaries() {
    let dir = tempdir();
    let path = dir.join("a.csv");
    fs::write(&path, "old").unwrap();
    write_atomic(&path, b"new").unwrap();
    assert_eq!(fs::read_to_string(&path).unwrap(), "new");
    let names: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("a.csv")]);
    // Into a missing directory: an error naming the target, nothing created.
    let missing = dir.join("no/such/dir/a.csv");
    let e = write_atomic(&missing, b"x").unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}: cannot write: ", missing.display())),
        "{e}"
    );
    // Over a directory: the rename fails and the temporary file is removed.
    fs::create_dir(dir.join("sub.csv")).unwrap();
    assert!(write_atomic(&dir.join("sub.csv"), b"x").is_err());
    let mut names: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(
        names,
        vec![std::ffi::OsString::from("a.csv"), "sub.csv".into()]
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ensure_distinct_sees_through_paths_and_links() {
    let dir = tempdir();
    let input = dir.join("in.csv");
    fs::write(&input, SQUARE).unwrap();
    fs::create_dir(dir.join("sub")).unwrap();
    assert!(ensure_distinct(&input, &dir.join("out.csv")).is_ok());
    assert!(ensure_distinct(&input, &dir.join("no/such/out.csv")).is_ok());
    let e = ensure_distinct(&input, &dir.join("sub/../in.csv")).unwrap_err();
    assert!(matches!(e, IoError::SameFile { .. }));
    assert!(e.to_string().starts_with("refusing to write "), "{e}");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&input, dir.join("link.csv")).unwrap();
        assert!(ensure_distinct(&input, &dir.join("link.csv")).is_err());
        fs::hard_link(&input, dir.join("hard.csv")).unwrap();
        assert!(ensure_distinct(&input, &dir.join("hard.csv")).is_err());
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn read_errors_name_the_file() {
    let e = read_points(Path::new("/no/such/file.csv"), &ReadOptions::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/no/such/file.csv: cannot read: "), "{e}");
    let dir = tempdir();
    let p = dir.join("curve.json");
    fs::write(
        &p,
        r#"{"degree": 2, "knots": [0, 0, 0, 1, 1, 1], "control_points": [[0, 0], [1, 2], [2, 0]]}"#,
    )
    .unwrap();
    assert!(matches!(
        read_points(&p, &ReadOptions::DEFAULT),
        Err(IoError::CurveNotPoints { .. })
    ));
    assert_eq!(read_curve_json(&p).unwrap().degree(), 2);
    let csv = dir.join("c.csv");
    fs::write(&csv, SQUARE).unwrap();
    assert!(matches!(
        read_curve_json(&csv),
        Err(IoError::UnknownFormat { .. })
    ));
    fs::remove_dir_all(&dir).unwrap();
}
