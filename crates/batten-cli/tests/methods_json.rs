//! `batten methods --json`: the registry as JSON, the same entries as the text listing.

#![allow(clippy::unwrap_used)]

use std::process::Command;

use serde_json::Value;

fn methods(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_batten"))
        .arg("methods")
        .args(args)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.stderr.is_empty());
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn json_lists_every_method_of_the_text_listing_with_typed_parameters() {
    let text = methods(&[]);
    let raw = methods(&["--json"]);
    // Keys in the documented order.
    let at = |k: &str| raw.find(&format!("\"{k}\":")).unwrap();
    assert!(at("name") < at("summary") && at("summary") < at("closed_curves"));
    assert!(at("closed_curves") < at("bspline_input") && at("bspline_input") < at("parameters"));
    let json: Value = serde_json::from_str(&raw).unwrap();
    let list = json.as_array().unwrap();
    assert_eq!(list.len(), batten::fair::methods().len());
    // The default method comes first, as in the text listing.
    assert_eq!(list[0]["name"], batten::fair::default_method());
    assert!(text.starts_with(&format!("{} (default)\n", batten::fair::default_method())));
    for m in list {
        let obj = m.as_object().unwrap();
        let mut keys: Vec<&str> = obj.keys().map(String::as_str).collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            [
                "bspline_input",
                "closed_curves",
                "name",
                "parameters",
                "summary"
            ]
        );
        let name = m["name"].as_str().unwrap();
        let summary = m["summary"].as_str().unwrap();
        assert!(
            text.contains(&format!("{name}\n  {summary}\n"))
                || text.contains(&format!("{name} (default)\n  {summary}\n")),
            "{name}"
        );
        let closed = if m["closed_curves"].as_bool().unwrap() {
            "yes"
        } else {
            "no"
        };
        assert!(
            text.contains(&format!("  {summary}\n  closed curves: {closed}\n")),
            "{name}"
        );
        for p in m["parameters"].as_array().unwrap() {
            let (pn, default) = (p["name"].as_str().unwrap(), p["default"].as_str().unwrap());
            assert!(text.contains(&format!("{pn}={default}")), "{name}.{pn}");
            let kind = p["type"].as_str().unwrap();
            assert!(
                ["number", "integer", "boolean", "choice", "text"].contains(&kind),
                "{name}.{pn}: {kind}"
            );
            match kind {
                "boolean" => assert!(default == "true" || default == "false"),
                "integer" => assert!(default.parse::<i64>().is_ok(), "{default}"),
                _ => {}
            }
            assert!(!p["doc"].as_str().unwrap().is_empty());
        }
    }
    let salvi = list.iter().find(|m| m["name"] == "salvi").unwrap();
    assert_eq!(salvi["bspline_input"], true);
    let mst = list.iter().find(|m| m["name"] == "mst").unwrap();
    assert_eq!(mst["bspline_input"], false);
}
