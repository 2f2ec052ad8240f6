//! Writing files: the only place that creates them.
//!
//! Renderers return bytes; [`write_new`] puts them on disk. It writes to a
//! temporary file in the target's directory and renames it into place, so a
//! reader never sees a half-written file and a failure leaves nothing behind.
//! It refuses to replace an existing file unless `force` is set
//! (`../shared/spec/style.md` §1, after hyperfine's `ExportManager` and
//! tempfile's `persist`).

use std::io::Write;
use std::path::{Path, PathBuf};

/// Why a file was not written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The target exists and `force` was not given.
    #[error("{path}: already exists; use --force to replace it", path = path.display())]
    Exists {
        /// The target.
        path: PathBuf,
    },
    /// The file system refused.
    #[error("{path}: {source}", path = path.display())]
    Io {
        /// The target.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
}

/// Writes `contents` to `path` atomically; refuses an existing file unless `force`.
pub fn write_new(path: &Path, contents: &[u8], force: bool) -> Result<(), OutputError> {
    let io_error = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    if !force && path.exists() {
        return Err(OutputError::Exists {
            path: path.to_path_buf(),
        });
    }
    let directory = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    // tempfile creates its files 0600, right for a secret but wrong for a
    // table or a report that others must read: ask for 0666 and let the
    // umask decide, as `File::create` (and any editor) does.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut temporary = builder.tempfile_in(directory).map_err(io_error)?;
    temporary.write_all(contents).map_err(io_error)?;
    temporary.as_file().sync_all().map_err(io_error)?;
    if force {
        temporary.persist(path).map_err(|e| io_error(e.error))?;
    } else {
        // persist_noclobber is not atomic on every platform, hence the check above too.
        temporary.persist_noclobber(path).map_err(|e| {
            if e.error.kind() == std::io::ErrorKind::AlreadyExists {
                OutputError::Exists {
                    path: path.to_path_buf(),
                }
            } else {
                io_error(e.error)
            }
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_refuses_and_replaces_with_force() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("X.COM");
        write_new(&path, b"first", false).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        let refused = write_new(&path, b"second", false).unwrap_err();
        assert!(refused.to_string().contains("--force"), "{refused}");
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        write_new(&path, b"second", true).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let leftovers = std::fs::read_dir(directory.path()).unwrap().count();
        assert_eq!(leftovers, 1, "no temporary file may remain");
    }

    #[cfg(unix)]
    #[test]
    fn files_get_the_permissions_file_create_gives() {
        use std::os::unix::fs::PermissionsExt;
        let directory = tempfile::tempdir().unwrap();
        let ordinary = directory.path().join("ordinary");
        std::fs::File::create(&ordinary).unwrap();
        let written = directory.path().join("X.COM");
        write_new(&written, b"x", false).unwrap();
        let mode = |path: &Path| std::fs::metadata(path).unwrap().permissions().mode() & 0o777;
        // Under the usual umask 022 that is 0644; the old 0600 failed here.
        assert_eq!(mode(&written), mode(&ordinary));
    }

    #[test]
    fn missing_directory_is_an_error_not_a_panic() {
        let error = write_new(Path::new("/nonexistent-axcomp-dir/x.txt"), b"x", false).unwrap_err();
        assert!(matches!(error, OutputError::Io { .. }));
    }
}
