//! The model-response corpus under `fixtures/responses/`: every file parses to its expected
//! value or fails with its expected typed error (see `expected.json` there).

use std::path::PathBuf;

use nesy_core::text::{ParseError, ParseErrorKind};
use nesy_core::text::{parse_induction_reply, parse_procedure, parse_refinement_reply, parse_state_list};
use nesy_core::{PatchError, apply_patch};
use serde_json::Value;

fn dir() -> PathBuf {
    nesy_testkit::workspace_root().join("fixtures/responses")
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

fn check_error(file: &str, err: ParseError, expected: &Value) {
    let kind: ParseErrorKind = serde_json::from_value(expected["kind"].clone()).unwrap();
    assert_eq!(err.kind, kind, "{file}: {err}");
    if let Some(line) = expected.get("line") {
        assert_eq!(err.line as u64, line.as_u64().unwrap(), "{file}: {err}");
    }
    if let Some(col) = expected.get("column") {
        assert_eq!(err.column as u64, col.as_u64().unwrap(), "{file}: {err}");
    }
    assert!(!err.expected.is_empty());
}

#[test]
fn corpus_matches_expectations() {
    let expected: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("expected.json")).unwrap()).unwrap();
    let procedure =
        parse_procedure(&std::fs::read_to_string(dir().join("procedure-hinge.txt")).unwrap()).unwrap();
    assert_eq!(procedure.len(), 4);
    let cases = expected["cases"].as_array().unwrap();
    assert!(cases.len() >= 20, "the corpus must hold at least 20 responses");
    let mut files_on_disk: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".txt") && n != "procedure-hinge.txt")
        .collect();
    files_on_disk.sort();
    let mut listed: Vec<String> = cases
        .iter()
        .map(|c| c["file"].as_str().unwrap().to_string())
        .collect();
    listed.sort();
    assert_eq!(files_on_disk, listed, "every response file has an expectation");

    for case in cases {
        let file = case["file"].as_str().unwrap();
        let text = std::fs::read_to_string(dir().join(file)).unwrap();
        match case["kind"].as_str().unwrap() {
            "induction" => match (parse_induction_reply(&text), case.get("ok")) {
                (Ok(r), Some(ok)) => {
                    assert_eq!(r.operator.name, ok["name"].as_str().unwrap(), "{file}");
                    let pre: Vec<String> = r.operator.pre.iter().map(|f| f.to_string()).collect();
                    let eff: Vec<String> = r.operator.eff.iter().map(|f| f.to_string()).collect();
                    assert_eq!(pre, strings(&ok["pre"]), "{file}");
                    assert_eq!(eff, strings(&ok["eff"]), "{file}");
                }
                (Err(e), None) => check_error(file, e, &case["error"]),
                (r, _) => panic!("{file}: unexpected {r:?}"),
            },
            "refinement" => match (parse_refinement_reply(&text), case.get("ok")) {
                (Ok(r), Some(ok)) => {
                    let patches = ok["patches"].as_array().unwrap();
                    assert_eq!(r.patches.len(), patches.len(), "{file}");
                    for (p, want) in r.patches.iter().zip(patches) {
                        let names = |ops: &[nesy_core::Operator]| {
                            ops.iter().map(|o| o.name.clone()).collect::<Vec<_>>()
                        };
                        assert_eq!(names(&p.search), strings(&want["search"]), "{file}");
                        assert_eq!(names(&p.replace), strings(&want["replace"]), "{file}");
                    }
                    if let Some(c) = ok.get("rationale_contains") {
                        assert!(
                            r.rationale.as_deref().unwrap_or("").contains(c.as_str().unwrap()),
                            "{file}: {:?}",
                            r.rationale
                        );
                    }
                    if let Some(apply) = case.get("apply") {
                        let near = apply["near"].as_u64().unwrap() as usize;
                        match (apply_patch(&procedure, &r.patches[0], near), apply.get("at")) {
                            (Ok(a), Some(at)) => assert_eq!(a.at as u64, at.as_u64().unwrap(), "{file}"),
                            (Err(PatchError::NoMatch { closest: Some(c), .. }), None) => {
                                assert_eq!(
                                    c.start as u64,
                                    apply["no_match_closest"].as_u64().unwrap(),
                                    "{file}"
                                );
                            }
                            (other, _) => panic!("{file}: unexpected {other:?}"),
                        }
                    }
                }
                (Err(e), None) => check_error(file, e, &case["error"]),
                (r, _) => panic!("{file}: unexpected {r:?}"),
            },
            "state" => {
                let s = parse_state_list(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
                let atoms: Vec<String> = s.sorted_by_text().iter().map(|a| a.to_string()).collect();
                assert_eq!(atoms, strings(&case["ok"]["atoms"]), "{file}");
            }
            other => panic!("unknown kind {other}"),
        }
    }
}
