//! The repository's reference data are the files `data/README.md` describes, byte for byte: each
//! file's SHA-256 is read from that table and checked against the file on disk.

mod common;

use sha2::{Digest, Sha256};

#[test]
fn every_reference_file_has_the_sha256_its_readme_states() {
    let readme = std::fs::read_to_string(common::root().join("data/README.md")).unwrap();
    let mut checked = 0;
    for line in readme.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let name = cells[1].trim_matches('`');
        let stated = cells[cells.len() - 2].trim_matches('`');
        let bytes = std::fs::read(common::data(name)).unwrap();
        let actual = format!("{:x}", Sha256::digest(&bytes));
        assert_eq!(
            actual, stated,
            "data/{name}: its SHA-256 differs from data/README.md"
        );
        checked += 1;
    }
    assert_eq!(checked, 8, "data/README.md lists eight files");
}
