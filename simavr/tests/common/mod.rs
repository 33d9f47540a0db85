//! Shared by the card tests: a folder of job files to image.

use std::collections::BTreeMap;
use std::path::PathBuf;

/// A folder of job files: 8.3 names in mixed case, a
/// multi-cluster file of `big_bytes`, an empty file and a subfolder.
pub fn job_folder(tag: &str, big_bytes: usize) -> (PathBuf, BTreeMap<String, Vec<u8>>) {
    let dir = std::env::temp_dir().join(format!("taut-fat-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("Gcode")).unwrap();
    let mut seed = 0x2545_F491u32;
    let big: Vec<u8> = (0..big_bytes)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as u8
        })
        .collect();
    let poradi: String = (0..3000).map(|i| format!("{},", i * 7 % 200)).collect();
    let files: [(&str, Vec<u8>); 6] = [
        ("param.txt", b"tvar = 1\r\npocet_hrebiku = 200\r\n".to_vec()),
        ("PORADI.TXT", format!("3000,\n{poradi}").into_bytes()),
        ("Machine.Txt", b"# overrides\nbase.accel = 4000\n".to_vec()),
        ("BIG.BIN", big),
        ("EMPTY", Vec::new()),
        ("Gcode/Part1.gco", b"G28\nG1 X10 Y10 F3000\n".to_vec()),
    ];
    let mut expected = BTreeMap::new();
    for (name, bytes) in files {
        std::fs::write(dir.join(name), &bytes).unwrap();
        expected.insert(name.to_owned(), bytes);
    }
    (dir, expected)
}
