//! The CSV/whitespace text reader on arbitrary bytes: never a panic; a point list it accepts
//! (planar `x,y` or space `x,y,z`) is finite, within the coordinate limit, free of
//! (near-)duplicate neighbours, has one line number per point, increasing, and writes back
//! and reads back bit for bit.
#![no_main]

use std::path::Path;

use batten::io::{self, Format, Origin, Pick, ReadOptions, Source};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for closed in [false, true] {
        let options = ReadOptions::default().with_closed(closed);
        if let Ok(d) = io::parse_points(data, Format::Text, Path::new("f.csv"), &options) {
            let pts = d.seq.points();
            assert!(pts.len() >= batten::PointSeq::MIN_POINTS);
            assert_eq!(d.lines.len(), pts.len());
            assert!(d.lines.windows(2).all(|w| w[0] < w[1]));
            assert!(
                pts.iter()
                    .all(|p| p.x.abs() <= io::MAX_COORDINATE && p.y.abs() <= io::MAX_COORDINATE)
            );
            // What is read writes back and reads back bit for bit.
            let text = io::encode_points(Path::new("f.csv"), pts, false, None).unwrap();
            let back = io::parse_points(&text, Format::Text, Path::new("f.csv"), &options).unwrap();
            assert_eq!(back.seq.points(), pts);
        }
        // Space curves: the same contract.
        let any = io::parse_input(
            data,
            Format::Text,
            Path::new("f.csv"),
            &options,
            &Pick::default(),
        );
        if let Ok(io::Input {
            source: Source::Space(d),
            ..
        }) = any
        {
            let pts = d.seq.points();
            assert!(pts.len() >= batten::SpaceSeq::MIN_POINTS);
            assert_eq!(d.lines.len(), pts.len());
            assert!(d.lines.windows(2).all(|w| w[0] < w[1]));
            assert!(pts.iter().flatten().all(|c| c.abs() <= io::MAX_COORDINATE));
            let text = io::format_space_points(
                Format::Text,
                Path::new("f.csv"),
                pts,
                false,
                &Origin::default(),
            )
            .unwrap();
            let back = io::parse_input(
                &text,
                Format::Text,
                Path::new("f.csv"),
                &options,
                &Pick::default(),
            )
            .unwrap();
            let Source::Space(b) = back.source else {
                panic!("a space curve read back as something else")
            };
            assert_eq!(b.seq.points(), pts);
        }
    }
});
