//! The JSON point-list reader on arbitrary bytes: never a panic; what it accepts is finite,
//! has one line per point and tangents matching the points.
#![no_main]

use std::path::Path;

use batten::io::{self, Format, ReadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(d) = io::parse_points(
        data,
        Format::Json,
        Path::new("f.json"),
        &ReadOptions::DEFAULT,
    ) {
        let pts = d.seq.points();
        assert_eq!(d.lines.len(), pts.len());
        assert!(pts.iter().all(|p| p.is_finite()));
        if let Some(t) = &d.tangents {
            assert_eq!(t.len(), pts.len());
        }
        let text = io::encode_points(
            Path::new("f.json"),
            pts,
            d.seq.is_closed(),
            d.tangents.as_deref(),
        )
        .unwrap();
        let back = io::parse_points(
            &text,
            Format::Json,
            Path::new("f.json"),
            &ReadOptions::DEFAULT,
        )
        .unwrap();
        assert_eq!(back.seq, d.seq);
    }
});
