//! Writing what a command makes without ever losing what the maker has.
//!
//! - A run names every input and every output before it writes anything;
//!   an output that is one of the inputs (the same file, by any path,
//!   link or case) or two outputs that are one file refuse the run
//!   ([`refuse_overwriting`]).
//! - Every file is first written whole to a hidden temporary file in its
//!   own folder, then renamed over its name ([`Batch`]): a run killed at
//!   any moment leaves each output as it was or as it is now, never half
//!   of one. A batch writes all its temporary files before it renames the
//!   first, so the files of one run (a card's `param.txt` and
//!   `poradi.txt`) change within a few microseconds of each other.
//! - A derived file's name comes from the output's, never from an
//!   input's: `-o horse.gcode` previews to `horse.preview.png`
//!   ([`derived`]).

use std::io::Write;
use std::path::{Path, PathBuf};

/// `out` with its extension replaced by `.<what>.<ext>`:
/// `horse.gcode` → `horse.preview.png`.
pub fn derived(out: &Path, what: &str, ext: &str) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    out.with_file_name(format!("{stem}.{what}.{ext}"))
}

/// Whether `a` and `b` are one file: the same device and inode when both
/// exist (links, `..`, a case-folding file system), else the same
/// absolute path.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => identity(&x) == identity(&y),
        (Err(_), Err(_)) => absolute(a) == absolute(b),
        _ => false,
    }
}

#[cfg(unix)]
fn identity(m: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (m.dev(), m.ino())
}

#[cfg(not(unix))]
fn identity(m: &std::fs::Metadata) -> (u64, u64) {
    (m.len(), 0)
}

/// The path made absolute, its existing folder resolved.
fn absolute(p: &Path) -> PathBuf {
    let full = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    match (full.parent(), full.file_name()) {
        (Some(dir), Some(name)) => std::fs::canonicalize(dir)
            .map(|d| d.join(name))
            .unwrap_or(full),
        _ => full,
    }
}

/// Refuses a run before it writes anything: when an output is one of the
/// inputs, or two outputs are one file.
pub fn refuse_overwriting(inputs: &[&Path], outputs: &[&Path]) -> Result<(), String> {
    for (k, out) in outputs.iter().enumerate() {
        if let Some(input) = inputs.iter().find(|i| same_file(i, out)) {
            return Err(format!(
                "{} is an input of this run ({}): it is never written over; choose another output name",
                out.display(),
                input.display()
            ));
        }
        if let Some(other) = outputs[..k].iter().find(|o| same_file(o, out)) {
            return Err(format!(
                "{} and {} are the same file: give them different names",
                other.display(),
                out.display()
            ));
        }
    }
    Ok(())
}

/// Files to write together, each atomically.
#[derive(Default)]
pub struct Batch {
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl Batch {
    pub fn new() -> Batch {
        Batch::default()
    }

    pub fn add(&mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) {
        self.files.push((path.into(), bytes.into()));
    }

    /// Writes every file to a temporary file beside it, then renames each
    /// over its name.
    pub fn commit(self) -> Result<(), String> {
        let mut ready = Vec::new();
        for (path, bytes) in self.files {
            ready.push((temporary(&path, &bytes)?, path));
        }
        for (tmp, path) in ready {
            tmp.persist(&path)
                .map_err(|e| format!("{}: {}", path.display(), e.error))?;
        }
        Ok(())
    }
}

/// One file, atomically.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let mut b = Batch::new();
    b.add(path, bytes);
    b.commit()
}

/// `bytes` in a hidden temporary file in `path`'s folder (`.NAME.XXXXXX.tmp`),
/// flushed to the disk.
fn temporary(path: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile, String> {
    let fail = |e: std::io::Error| format!("{}: {e}", path.display());
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    // As a new file would be made (the umask applies).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = b.tempfile_in(dir).map_err(fail)?;
    tmp.write_all(bytes).map_err(fail)?;
    tmp.as_file().sync_all().map_err(fail)?;
    Ok(tmp)
}

/// `png` or `svg`, from the picture's name; anything else is refused.
pub fn picture_extension(out: &Path) -> Result<String, String> {
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" | "svg" => Ok(ext),
        _ => Err(format!(
            "{}: the picture must be .png or .svg",
            out.display()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("taut-output-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn derived_names_come_from_the_output() {
        assert_eq!(
            derived(Path::new("a/horse.gcode"), "preview", "png"),
            Path::new("a/horse.preview.png")
        );
        assert_eq!(
            derived(Path::new("horse"), "preview", "svg"),
            Path::new("horse.preview.svg")
        );
    }

    #[test]
    fn an_input_is_never_an_output() {
        let d = scratch("refuse");
        let input = d.join("horse.png");
        std::fs::write(&input, b"picture").unwrap();
        let roundabout = d.join("sub/../horse.png");
        std::fs::create_dir_all(d.join("sub")).unwrap();
        let e = refuse_overwriting(&[&input], &[&d.join("x.gcode"), &roundabout]).unwrap_err();
        assert!(e.contains("is an input of this run"), "{e}");
        #[cfg(unix)]
        {
            let link = d.join("link.png");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(refuse_overwriting(&[&input], &[&link]).is_err());
        }
        let e = refuse_overwriting(&[&input], &[&d.join("a.png"), &d.join("./a.png")]).unwrap_err();
        assert!(e.contains("are the same file"), "{e}");
        assert!(refuse_overwriting(&[&input], &[&d.join("horse.preview.png")]).is_ok());
        assert_eq!(std::fs::read(&input).unwrap(), b"picture");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_batch_replaces_whole_files_and_leaves_no_temporary() {
        let d = scratch("batch");
        std::fs::write(d.join("a.txt"), b"old").unwrap();
        let mut b = Batch::new();
        b.add(d.join("a.txt"), b"new a".to_vec());
        b.add(d.join("b.txt"), b"new b".to_vec());
        b.commit().unwrap();
        assert_eq!(std::fs::read(d.join("a.txt")).unwrap(), b"new a");
        assert_eq!(std::fs::read(d.join("b.txt")).unwrap(), b"new b");
        let names: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
        // A folder that is not there: nothing is written.
        let e = write(&d.join("no/such/c.txt"), b"x").unwrap_err();
        assert!(e.contains("no/such/c.txt"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
