//! Messages in a manifest's words.
//!
//! The precompute pipeline's errors and warnings give their advice as
//! `modal precompute` flags (`use --scale 0.001`, `a smaller --cell`). An
//! asset of a manifest has no flags: its settings are keys of the asset, a
//! glob or `[defaults]`. So the catalogue says `scale = 0.001` and
//! `a smaller cell`, naming what the user can change in the file they wrote.

/// `modal precompute` flags and the manifest keys that set the same thing.
const FLAG_KEYS: [(&str, &str); 9] = [
    ("--sheet-thickness", "sheet_thickness"),
    ("--transfer-max-freq", "transfer_max_freq"),
    ("--min-freq", "min_freq"),
    ("--max-freq", "max_freq"),
    ("--scale", "scale"),
    ("--order", "order"),
    ("--modes", "modes"),
    ("--cell", "cell"),
    ("--part", "part"),
];

/// `message` with each flag of [`FLAG_KEYS`] named by its manifest key:
/// `--scale 0.001` becomes `scale = 0.001`, a flag without a value its key.
/// Flags with no manifest key (`--threads`, the batch's own) are kept, and
/// so is a message that already names the manifest's spelling.
pub fn in_manifest_terms(message: &str) -> String {
    if message.contains("manifest") {
        // Already says how a manifest sets it (the unit advice does).
        return message.to_string();
    }
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    'scan: while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let tail = &rest[at..];
        for (flag, key) in FLAG_KEYS {
            let Some(after) = tail.strip_prefix(flag) else { continue };
            if after.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
                continue; // a longer flag
            }
            out.push_str(key);
            let value_follows = after
                .strip_prefix(' ')
                .is_some_and(|v| v.starts_with(|c: char| c.is_ascii_digit() || c == '.' || c == '-'));
            if value_follows {
                out.push_str(" =");
            }
            rest = after;
            continue 'scan;
        }
        out.push_str("--");
        rest = &tail[2..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_become_keys_and_values_are_assigned() {
        let cases = [
            (
                "the bounding box diagonal is 180.3 m: if the file is in millimetres use --scale 0.001",
                "the bounding box diagonal is 180.3 m: if the file is in millimetres use scale = 0.001",
            ),
            (
                "use a coarser mesh (a larger --cell) or --order 1",
                "use a coarser mesh (a larger cell) or order = 1",
            ),
            ("give --cell 1.2e-3 or fewer parts", "give cell = 1.2e-3 or fewer parts"),
            ("(--sheet-thickness M)", "(sheet_thickness M)"),
            (
                "--max-freq (20000) must be above --min-freq (0)",
                "max_freq (20000) must be above min_freq (0)",
            ),
            // Not a manifest key, or not a flag at all: kept.
            ("--threads must be between 1 and 1024", "--threads must be between 1 and 1024"),
            ("a -- b, --cells, --", "a -- b, --cells, --"),
            // Messages that already give the manifest's spelling stay as they are.
            (
                "(--scale 0.001, or `scale = 0.001` in a scene or manifest)",
                "(--scale 0.001, or `scale = 0.001` in a scene or manifest)",
            ),
        ];
        for (message, want) in cases {
            assert_eq!(in_manifest_terms(message), want);
        }
    }
}
