//! Writing whole files so that nothing is ever left half-written: every result file of gyrodrift
//! (tables, images, reports, check and diagnosis output) goes through [`write_atomic`].

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically: a temporary file beside it (in the same folder, so the
/// rename cannot cross file systems), written and synced, then renamed over the target. The
/// folder is created if missing. On any error the target is untouched and the temporary removed.
///
/// The file is created with the process's umask, like the recordings, so colleagues and CI jobs
/// read results as they read data.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let temporary = temporary_beside(path);
    let result = fs::File::create(&temporary)
        .and_then(|mut file| {
            file.write_all(bytes)?;
            file.sync_all()
        })
        .and_then(|()| fs::rename(&temporary, path));
    if result.is_err() {
        // Best effort: the temporary may not even exist.
        let _ = fs::remove_file(&temporary);
    }
    result
}

/// [`write_atomic`] into a folder that may not exist yet: the folder is created first. For result
/// folders a command makes (tables, reports); a file a caller names keeps the plain rule.
pub fn write_atomic_creating_folder(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(dir)?;
    }
    write_atomic(path, bytes)
}

/// A name beside `path` that no other writer in this or another process uses at the same time.
fn temporary_beside(path: &Path) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    path.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.json");
        let nested = dir.path().join("missing").join("x");
        assert!(write_atomic(&nested, b"no").is_err());
        write_atomic_creating_folder(&nested, b"yes").unwrap();
        assert_eq!(fs::read(&nested).unwrap(), b"yes");
        fs::remove_dir_all(dir.path().join("missing")).unwrap();
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("result.json")]);
    }

    #[test]
    fn a_failed_write_leaves_the_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        // The target is a folder: the rename fails, the temporary is removed.
        let path = dir.path().join("taken");
        fs::create_dir(&path).unwrap();
        fs::write(path.join("inside"), b"kept").unwrap();
        assert!(write_atomic(&path, b"new").is_err());
        assert_eq!(fs::read(path.join("inside")).unwrap(), b"kept");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
