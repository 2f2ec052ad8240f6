//! Writing files: the only place that creates them.
//!
//! Renderers return bytes; [`write_new`] puts them on disk. It writes to a
//! temporary file in the target's directory and renames it into place, so a
//! reader never sees a half-written file and a failure leaves nothing behind.
//! It refuses to replace an existing file unless `force` is set
//! (`../shared/spec/style.md` §1, after hyperfine's `ExportManager` and
//! tempfile's `persist`). It also refuses, `--force` or not, a target that is
//! one of the command's inputs (the same file by any path or hard link):
//! `convert X.rtl -o X.rtl --force` must not replace the only copy of a
//! measurement with a table.

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
    /// The folder the file goes into does not exist (nothing is created:
    /// a mistyped folder must not become a new one).
    #[error("cannot write {path}: the folder {folder} does not exist", path = path.display(), folder = folder.display())]
    NoFolder {
        /// The target.
        path: PathBuf,
        /// Its folder.
        folder: PathBuf,
    },
    /// The target is a file the command reads (`--force` does not change that).
    #[error("{path}: is also an input of this command ({input}); writing it would replace that file: name another output", path = path.display(), input = input.display())]
    Input {
        /// The target.
        path: PathBuf,
        /// The input it is, as the user named it.
        input: PathBuf,
    },
    /// The same file was named for two of the outputs of one command.
    #[error("{path}: named for two outputs; give each output its own file", path = path.display())]
    Twice {
        /// The target named twice.
        path: PathBuf,
    },
    /// The file system refused.
    ///
    /// The operating system's message is part of the text, not a `source`
    /// (printed with the chain it appeared twice), and never names the
    /// temporary file the target is written through.
    #[error("cannot write {path}: {error}", path = path.display())]
    Io {
        /// The target.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
}

/// The operating system's error without the temporary file's path that
/// `tempfile` wraps around it (`… at path "out/.tmpXXXX"`): the user never
/// asked for that file.
fn os_error(error: std::io::Error) -> std::io::Error {
    // tempfile 3 hides the OS error in a private type whose text is
    // `{os error} at path {path:?}` and whose `source` is the OS error's
    // (none); its text is all there is to take the path off.
    let Some(inner) = error.get_ref() else {
        return error;
    };
    let text = inner.to_string();
    match text.rfind(" at path ") {
        Some(at) => std::io::Error::new(error.kind(), &text[..at]),
        None => error,
    }
}

/// Writes `contents` to `path` atomically; refuses an existing file unless
/// `force`, and any of the command's `inputs` always.
pub fn write_new(
    path: &Path,
    contents: &[u8],
    inputs: &[&Path],
    force: bool,
) -> Result<(), OutputError> {
    write_all_new(&[(path, contents)], inputs, force)
}

/// Writes several files as one result: all of them or none.
///
/// Every target is checked first (none may be one of the command's
/// `inputs`, none may exist without `force`, none may be named twice), then every file is written to a temporary file beside its
/// target, and only when all are on disk are they renamed into place. A
/// failure before the renames leaves nothing; a failure during them (the
/// file system refusing a rename) removes the files this call created, so a
/// command whose second output is refused never leaves its first behind.
/// What `force` replaced cannot be restored.
pub fn write_all_new<P: AsRef<Path>, B: AsRef<[u8]>>(
    files: &[(P, B)],
    inputs: &[&Path],
    force: bool,
) -> Result<(), OutputError> {
    for (index, (path, _)) in files.iter().enumerate() {
        let path = path.as_ref();
        if let Some(input) = inputs.iter().find(|input| same_file(input, path)) {
            return Err(OutputError::Input {
                path: path.to_path_buf(),
                input: input.to_path_buf(),
            });
        }
        if files[..index]
            .iter()
            .any(|(p, _)| same_file(p.as_ref(), path))
        {
            return Err(OutputError::Twice {
                path: path.to_path_buf(),
            });
        }
        if !force && path.exists() {
            return Err(OutputError::Exists {
                path: path.to_path_buf(),
            });
        }
    }
    let mut staged = Vec::with_capacity(files.len());
    for (path, contents) in files {
        let path = path.as_ref();
        staged.push((path, stage(path, contents.as_ref())?, path.exists()));
    }
    let mut created: Vec<&Path> = Vec::new();
    for (path, temporary, existed) in staged {
        let persisted = if force {
            temporary.persist(path).map(|_| ())
        } else {
            temporary.persist_noclobber(path).map(|_| ())
        };
        if let Err(e) = persisted {
            for path in &created {
                let _ = std::fs::remove_file(path);
            }
            return Err(if e.error.kind() == std::io::ErrorKind::AlreadyExists {
                OutputError::Exists {
                    path: path.to_path_buf(),
                }
            } else {
                OutputError::Io {
                    path: path.to_path_buf(),
                    error: os_error(e.error),
                }
            });
        }
        if !existed {
            created.push(path);
        }
    }
    Ok(())
}

/// Creates the folder `directory` for a command's files when it is missing,
/// but only where its parent exists: a mistyped path (`--png /no/such/dir`)
/// is refused, not made into a tree of new folders. Whether it was created
/// (for the caller to remove again if nothing is written).
pub fn create_folder(directory: &Path) -> Result<bool, OutputError> {
    if directory.is_dir() {
        return Ok(false);
    }
    folder_of(directory)?;
    std::fs::create_dir(directory).map_err(|error| OutputError::Io {
        path: directory.to_path_buf(),
        error,
    })?;
    Ok(true)
}

/// The folder `path` goes into, which must exist: a missing one is refused,
/// not created (a mistyped folder must not become a new one).
fn folder_of(path: &Path) -> Result<&Path, OutputError> {
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    if folder.is_dir() {
        Ok(folder)
    } else {
        Err(OutputError::NoFolder {
            path: path.to_path_buf(),
            folder: folder.to_path_buf(),
        })
    }
}

/// `a` and `b` name one file: the same path, or (when both exist) the same
/// file by another path or another hard link.
fn same_file(a: &Path, b: &Path) -> bool {
    if a == b {
        return true;
    }
    #[cfg(unix)]
    if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        use std::os::unix::fs::MetadataExt;
        return (ma.dev(), ma.ino()) == (mb.dev(), mb.ino());
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        // A file that does not exist yet: compare its directory and name.
        _ => match (
            a.parent().map(absolute_directory),
            b.parent().map(absolute_directory),
        ) {
            (Some(Some(da)), Some(Some(db))) => da == db && a.file_name() == b.file_name(),
            _ => false,
        },
    }
}

fn absolute_directory(directory: &Path) -> Option<PathBuf> {
    if directory.as_os_str().is_empty() {
        Path::new(".").canonicalize().ok()
    } else {
        directory.canonicalize().ok()
    }
}

/// `contents` in a temporary file in `path`'s directory, synced to disk.
/// A missing directory is refused, not created: a mistyped folder must not
/// become a new one.
fn stage(path: &Path, contents: &[u8]) -> Result<tempfile::NamedTempFile, OutputError> {
    let io_error = |error| OutputError::Io {
        path: path.to_path_buf(),
        error: os_error(error),
    };
    let directory = folder_of(path)?;
    #[cfg_attr(not(unix), allow(unused_mut))]
    let mut builder = tempfile::Builder::new();
    // tempfile creates its files 0600, right for a secret but wrong for a
    // table or a report that others must read: ask for 0666 and let the
    // umask decide, as `File::create` (and any editor) does.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut temporary = builder.tempfile_in(directory).map_err(io_error)?;
    temporary.write_all(contents).map_err(io_error)?;
    temporary.as_file().sync_all().map_err(io_error)?;
    Ok(temporary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_refuses_and_replaces_with_force() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("X.COM");
        write_new(&path, b"first", &[], false).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        let refused = write_new(&path, b"second", &[], false).unwrap_err();
        assert!(refused.to_string().contains("--force"), "{refused}");
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        write_new(&path, b"second", &[], true).unwrap();
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
        write_new(&written, b"x", &[], false).unwrap();
        let mode = |path: &Path| std::fs::metadata(path).unwrap().permissions().mode() & 0o777;
        // Under the usual umask 022 that is 0644; the old 0600 failed here.
        assert_eq!(mode(&written), mode(&ordinary));
    }

    #[test]
    fn missing_directory_is_an_error_not_a_panic() {
        let error =
            write_new(Path::new("/nonexistent-axcomp-dir/x.txt"), b"x", &[], false).unwrap_err();
        assert_eq!(
            error.to_string(),
            "cannot write /nonexistent-axcomp-dir/x.txt: the folder /nonexistent-axcomp-dir does not exist"
        );
    }

    #[test]
    fn os_errors_lose_the_temporary_path() {
        // What tempfile returns: an io::Error wrapping one that has the OS code.
        let directory = tempfile::tempdir().unwrap();
        let missing = directory.path().join("gone");
        let wrapped = tempfile::Builder::new().tempfile_in(&missing).unwrap_err();
        assert!(wrapped.to_string().contains("at path"), "{wrapped}");
        let plain = os_error(wrapped);
        assert_eq!(plain.kind(), std::io::ErrorKind::NotFound);
        assert_eq!(plain.to_string(), "No such file or directory (os error 2)");
    }

    #[test]
    fn several_files_are_written_all_or_none() {
        let directory = tempfile::tempdir().unwrap();
        let first = directory.path().join("before.rtl");
        let second = directory.path().join("after.rtl");
        std::fs::write(&second, b"kept").unwrap();
        // The second exists: the first must not be created.
        let refused = write_all_new(&[(&first, b"1"), (&second, b"2")], &[], false).unwrap_err();
        assert!(matches!(refused, OutputError::Exists { ref path } if *path == second));
        assert!(!first.exists());
        assert_eq!(std::fs::read(&second).unwrap(), b"kept");
        // One target in a folder that does not exist: nothing is written.
        let missing = directory.path().join("no-such-folder").join("x.png");
        let error = write_all_new(&[(&first, b"1"), (&missing, b"2")], &[], true).unwrap_err();
        assert!(matches!(error, OutputError::NoFolder { .. }));
        assert!(!first.exists());
        // The same file twice (also by another spelling) is refused before anything.
        let again = directory.path().join(".").join("before.rtl");
        let twice = write_all_new(&[(&first, b"1"), (&again, b"2")], &[], true).unwrap_err();
        assert!(matches!(twice, OutputError::Twice { .. }), "{twice}");
        assert!(!first.exists());
        // With --force all are written.
        write_all_new(&[(&first, b"1"), (&second, b"2")], &[], true).unwrap();
        assert_eq!(std::fs::read(&first).unwrap(), b"1");
        assert_eq!(std::fs::read(&second).unwrap(), b"2");
        let leftovers = std::fs::read_dir(directory.path()).unwrap().count();
        assert_eq!(leftovers, 2, "no temporary file may remain");
    }

    #[test]
    fn an_input_is_never_an_output() {
        let directory = tempfile::tempdir().unwrap();
        let input = directory.path().join("X.rtl");
        std::fs::write(&input, b"measurement").unwrap();
        let other = directory.path().join("other.txt");
        // By the same path, by another spelling, by a hard link: refused
        // even with --force, and nothing else is written either.
        let link = directory.path().join("link.rtl");
        std::fs::hard_link(&input, &link).unwrap();
        for target in [
            input.clone(),
            directory.path().join(".").join("X.rtl"),
            link.clone(),
        ] {
            let error =
                write_all_new(&[(&other, b"1"), (&target, b"2")], &[&input], true).unwrap_err();
            assert!(matches!(error, OutputError::Input { .. }), "{error}");
            assert!(error.to_string().contains("also an input"), "{error}");
        }
        assert_eq!(std::fs::read(&input).unwrap(), b"measurement");
        assert!(!other.exists());
        write_new(&other, b"1", &[&input], false).unwrap();
    }
}
