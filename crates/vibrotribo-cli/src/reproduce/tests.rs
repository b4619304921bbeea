//! Every finding's verdict is computed from the run: no `ctx.finding(…)` call passes a
//! verdict written as a constant.

/// The source of every file of `reproduce`, by name.
const SOURCES: [(&str, &str); 18] = [
    ("bifmaps.rs", include_str!("bifmaps.rs")),
    ("chatter.rs", include_str!("chatter.rs")),
    ("command.rs", include_str!("command.rs")),
    ("configurations.rs", include_str!("configurations.rs")),
    ("context.rs", include_str!("context.rs")),
    ("coupling.rs", include_str!("coupling.rs")),
    ("design.rs", include_str!("design.rs")),
    ("draw.rs", include_str!("draw.rs")),
    ("dynamics.rs", include_str!("dynamics.rs")),
    ("extras.rs", include_str!("extras.rs")),
    ("mass_ratio.rs", include_str!("mass_ratio.rs")),
    ("mod.rs", include_str!("mod.rs")),
    ("orbits.rs", include_str!("orbits.rs")),
    ("overlay.rs", include_str!("overlay.rs")),
    ("report.rs", include_str!("report.rs")),
    ("runs.rs", include_str!("runs.rs")),
    ("spacing.rs", include_str!("spacing.rs")),
    ("vibration.rs", include_str!("vibration.rs")),
];

/// The top-level arguments of the call whose argument list opens at `text[0] == '('`.
fn arguments(text: &str) -> Vec<String> {
    let mut depth = 0usize;
    let mut args = vec![String::new()];
    let mut in_string = false;
    let mut escaped = false;
    for c in text.chars() {
        if in_string {
            if let Some(a) = args.last_mut() {
                a.push(c);
            }
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_string = true,
            '(' | '[' | '{' => {
                depth += 1;
                if depth == 1 {
                    continue;
                }
            }
            ')' | ']' | '}' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            ',' if depth == 1 => {
                args.push(String::new());
                continue;
            }
            _ => {}
        }
        if let Some(a) = args.last_mut() {
            a.push(c);
        }
    }
    args.retain(|a| !a.trim().is_empty());
    args
}

/// The verdict argument (the last) of every `ctx.finding(` call in `source`.
fn verdicts(source: &str) -> Vec<String> {
    source
        .match_indices("ctx.finding(")
        .filter_map(|(i, m)| arguments(&source[i + m.len() - 1..]).pop())
        .map(|a| a.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect()
}

fn is_constant(verdict: &str) -> bool {
    ["Verdict::Agrees", "Verdict::Partly", "Verdict::Differs"].contains(&verdict)
}

#[test]
fn no_verdict_is_a_constant() {
    let mut findings = 0;
    for (name, source) in SOURCES {
        for v in verdicts(source) {
            findings += 1;
            assert!(
                !is_constant(&v),
                "{name}: a finding's verdict is the constant {v}"
            );
        }
    }
    // The scan sees the findings (27 when this test was written); it would pass vacuously
    // if it found none.
    assert!(
        findings >= 20,
        "only {findings} findings found: the scan is broken"
    );
}

#[test]
fn the_scan_reads_every_file() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/reproduce");
    for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let name = entry
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .unwrap_or_default();
        if name.ends_with(".rs") && name != "tests.rs" {
            assert!(SOURCES.iter().any(|(n, _)| *n == name), "add {name} to SOURCES");
        }
    }
}

#[test]
fn the_scan_finds_a_constant_verdict() {
    let constant = r#"ctx.finding("7", "The paper (a, b).", format!("{x}, {y}"), Verdict::Agrees,);"#;
    assert_eq!(verdicts(constant), ["Verdict::Agrees"]);
    assert!(is_constant(&verdicts(constant)[0]));
    let computed = r#"ctx.finding("7", "p", ours, if ok { Verdict::Agrees } else { Verdict::Partly });"#;
    assert!(!is_constant(&verdicts(computed)[0]));
}

#[test]
fn verdict_of_counts() {
    use super::context::Verdict;
    assert_eq!(Verdict::of(0, 4), Verdict::Differs);
    assert_eq!(Verdict::of(2, 4), Verdict::Partly);
    assert_eq!(Verdict::of(4, 4), Verdict::Agrees);
}
