//! What may begin the name of a file in an output folder: a case's name, checked when the case
//! is read, begins the name of every file its runs write.

/// The longest name of a case (bytes), which every output file's name begins with.
pub const NAME_BYTES: usize = 200;

/// Whether `name` can begin the name of a file in an output folder without leaving it or
/// making a name that a terminal or a table would mangle: 1 to [`NAME_BYTES`] bytes, no `/`,
/// no control character, not `.` or `..`.
pub fn plain_file_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= NAME_BYTES
        && name != "."
        && name != ".."
        && !name.chars().any(|c| c == '/' || c.is_control())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_leave_the_folder_or_hold_control_characters_are_not_plain() {
        for bad in [
            "",
            ".",
            "..",
            "a/b",
            "../x",
            "a\nb",
            "a\u{1b}[31m",
            &"x".repeat(201),
        ] {
            assert!(!plain_file_name(bad), "{bad:?}");
        }
        for good in ["shear_flow", "a<b&c\"d", "..x", "é"] {
            assert!(plain_file_name(good), "{good:?}");
        }
    }
}
