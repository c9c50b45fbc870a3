//! Fuzz-style property: mutated scene files never panic the reader; they parse or give a
//! located error whose line and column lie inside the text.

use data::{CATALOG, parse_scene};
use proptest::prelude::*;

fn mutate(text: &str, ops: &[(u8, usize, u8)]) -> String {
    let mut bytes: Vec<u8> = text.as_bytes().to_vec();
    for &(op, pos, byte) in ops {
        if bytes.is_empty() {
            bytes.push(byte);
            continue;
        }
        let i = pos % bytes.len();
        match op % 5 {
            0 => bytes[i] = byte,
            1 => {
                bytes.remove(i);
            }
            2 => bytes.insert(i, byte),
            3 => {
                // duplicate a line: exercises duplicate keys and repeated tables
                let start = bytes[..i]
                    .iter()
                    .rposition(|&b| b == b'\n')
                    .map_or(0, |p| p + 1);
                let end = bytes[i..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(bytes.len(), |p| i + p + 1);
                let line = bytes[start..end].to_vec();
                bytes.splice(start..start, line);
            }
            _ => {
                // swap a digit for a sign or exponent: exercises numeric validation
                let replacement = [b'-', b'e', b'9', b'0', b'.', b'n'][byte as usize % 6];
                bytes[i] = replacement;
            }
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, .. ProptestConfig::default() })]
    #[test]
    fn prop_mutated_scenes_never_panic(
        which in 0..CATALOG.len(),
        ops in proptest::collection::vec((any::<u8>(), any::<usize>(), any::<u8>()), 1..6),
    ) {
        let text = mutate(CATALOG[which].1, &ops);
        match parse_scene(&text, "mutated.toml") {
            Ok(scene) => {
                // whatever parses must be fully valid: all numbers finite
                prop_assert!(scene.simulation.t_end.is_finite() && scene.simulation.t_end > 0.0);
            }
            Err(e) => {
                let lines = text.lines().count().max(1) + 1;
                prop_assert!(e.line >= 1 && e.line <= lines, "line {} of {}", e.line, lines);
                prop_assert!(e.column >= 1);
                prop_assert!(!e.message.is_empty() && !e.expected.is_empty());
            }
        }
    }
}
