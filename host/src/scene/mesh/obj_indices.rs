//! A check of an OBJ file's face indices, line by line, before `tobj` reads it.
//!
//! Why: `tobj` 4.0 turns a relative index `-k` into `count - k` with a signed-to-unsigned
//! cast, so a `-k` reaching before the first element (or a huge positive index) becomes an
//! index near `usize::MAX`, and its bounds check `i * 2 + 1` then overflows: a panic in a debug
//! build (found by the `obj` fuzz target). The check here rejects every such index with the
//! file and line, which `tobj`'s own error (`FaceTexCoordOutOfBounds`, no line) cannot give.
//!
//! Invariant: when this returns `Ok`, every index on an `f` or `l` line resolves, as `tobj`
//! resolves it, to an element that the file declares (negative: counted back from the elements
//! declared above the line; positive: at most the file's total).

use crate::scene::error::SceneError;
use std::path::Path;

/// The three kinds of element a face corner may index, in the order of `v/vt/vn`.
const KINDS: [(&str, &str); 3] = [("v", "vertex"), ("vt", "texture"), ("vn", "normal")];

/// Checks every face (`f`) and line (`l`) index of OBJ `bytes` against the elements the file
/// declares. Lines are split as `tobj` splits them (at `\n`, words at whitespace); the check
/// stops at the first line that is not UTF-8, where `tobj` stops with its own error.
pub fn check_obj_face_indices(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let mut declared = [0usize; 3];
    // Largest positive index per kind, with its line: checked against the totals at the end.
    let mut largest: [Option<(u64, usize)>; 3] = [None; 3];
    for (number, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = number + 1;
        let Ok(text) = std::str::from_utf8(raw) else {
            break;
        };
        let mut words = text.split_whitespace();
        let Some(word) = words.next() else {
            continue;
        };
        if let Some(kind) = KINDS.iter().position(|(k, _)| *k == word) {
            declared[kind] += 1;
            continue;
        }
        if word != "f" && word != "l" {
            continue;
        }
        for corner in words {
            for (kind, index) in corner.split('/').enumerate().take(3) {
                let Ok(index) = index.parse::<i64>() else {
                    continue; // empty (`v//vn`) or malformed: tobj reports the latter
                };
                if index < 0 && index.unsigned_abs() > declared[kind] as u64 {
                    return Err(SceneError::new(
                        path,
                        Some(line),
                        "face",
                        format!(
                            "{} index {index} reaches before the first {} \
                             ({} declared above this line)",
                            KINDS[kind].1, KINDS[kind].0, declared[kind]
                        ),
                    ));
                }
                if index > 0 && largest[kind].is_none_or(|(m, _)| index as u64 > m) {
                    largest[kind] = Some((index as u64, line));
                }
            }
        }
    }
    for (kind, largest) in largest.into_iter().enumerate() {
        let Some((index, line)) = largest else {
            continue;
        };
        if index > declared[kind] as u64 {
            return Err(SceneError::new(
                path,
                Some(line),
                "face",
                format!(
                    "{} index {index} is past the last {} (the file declares {})",
                    KINDS[kind].1, KINDS[kind].0, declared[kind]
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<(), SceneError> {
        check_obj_face_indices(Path::new("t.obj"), text.as_bytes())
    }

    const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";

    #[test]
    fn indices_in_range_pass() {
        check(&format!(
            "{TRIANGLE}f 1/1/1 2/1/1 3/1/1\nf -3/-1/-1 -2//-1 -1\nl 1 2\n"
        ))
        .unwrap();
    }

    #[test]
    fn relative_index_before_the_first_element_names_its_line() {
        let e = check(&format!("{TRIANGLE}f 1 2 3\nf 1//-2 2//1 3//1\n")).unwrap_err();
        assert_eq!(e.line, Some(7));
        assert!(e.message.contains("normal index -2"), "{e}");
        // Counted from the elements above the line, not the file's total.
        let e = check("v 0 0 0\nf -2 -1 -1\nv 1 0 0\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("vertex index -2"), "{e}");
        // The most negative i64 must not overflow the check itself.
        let e = check(&format!("{TRIANGLE}f 1/-9223372036854775808 2 3\n")).unwrap_err();
        assert!(e.message.contains("texture index"), "{e}");
    }

    #[test]
    fn positive_index_past_the_last_element_names_its_line() {
        let e = check(&format!("{TRIANGLE}f 1/9223372036854775807 2/1 3/1\n")).unwrap_err();
        assert_eq!(e.line, Some(6));
        assert!(
            e.message.contains("texture index 9223372036854775807"),
            "{e}"
        );
        // A forward reference within the file's total is left to tobj.
        check("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    }

    #[test]
    fn the_fuzz_finding_is_an_error_not_a_panic() {
        let e = crate::scene::mesh::parse_obj(Path::new("t.obj"), b"v 0 0 0\nf  4//-8 //-84\n")
            .unwrap_err();
        assert_eq!(e.line, Some(2), "{e}");
    }
}
