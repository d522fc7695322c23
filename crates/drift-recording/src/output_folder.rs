//! One rule for every writer's output folder: a missing or empty folder is used; a folder holding
//! the same writer's earlier output is replaced whole, and only when asked (`--force`,
//! `force=True`); a folder holding anything else is never deleted.
//!
//! A writer recognises its own output by a marker file ([`MARKER`], naming the command) or, for a
//! simulated campaign, by the names it writes. [`Staged`] writes a whole output into a temporary
//! folder beside the target and swaps it in at the end, so a failed run leaves the earlier output
//! as it was.

use std::path::{Path, PathBuf};

/// The file naming the command that wrote a folder.
pub const MARKER: &str = ".gyrodrift-output";

/// How a writer tells its own earlier output.
#[derive(Debug, Clone, Copy)]
pub enum Owned {
    /// The folder holds [`MARKER`] naming the writer's command.
    Marker,
    /// The folder holds nothing but these names.
    Names(&'static [&'static str]),
    /// The folder holds [`MARKER`] naming the writer's command or, written by a version that did
    /// not mark its output, nothing but these names.
    MarkerOrNames(&'static [&'static str]),
}

/// A command that writes an output folder.
#[derive(Debug, Clone, Copy)]
pub struct Writer {
    /// The command as typed after `gyrodrift`: `fit`, `import csv`.
    pub command: &'static str,
    /// What one run writes, singular: `campaign`, `report`, `tables folder`.
    pub product: &'static str,
    /// The gerund in messages: `simulating`, `fitting`.
    pub doing: &'static str,
    /// How its earlier output is recognised.
    pub owned: Owned,
}

/// Why a folder cannot take a writer's output. `flag` is how the caller asks to replace
/// (`--force`, `force=True`).
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    /// The folder holds the writer's earlier output and replacing was not asked for.
    #[error("{} is not empty ({}): {doing} into it would mix two {product}s; pass {flag} to replace the {product} there, or choose a new folder", path.display(), entries.join(", "))]
    NotEmpty {
        /// The folder.
        path: PathBuf,
        /// Its entries, sorted.
        entries: Vec<String>,
        /// The writer's gerund.
        doing: &'static str,
        /// What the writer writes.
        product: &'static str,
        /// How to ask for replacing.
        flag: &'static str,
    },
    /// The folder holds files the writer does not write.
    #[error("{} holds files `{command}` does not write ({}): {flag} replaces only a {product}; choose a new folder", path.display(), names.join(", "))]
    Foreign {
        /// The folder.
        path: PathBuf,
        /// The foreign entries, sorted.
        names: Vec<String>,
        /// The writer's command.
        command: &'static str,
        /// What the writer writes.
        product: &'static str,
        /// How replacing is asked for.
        flag: &'static str,
    },
    /// The folder holds what the writer writes but no [`MARKER`]: its output from a version that
    /// did not mark it, and replacing was not asked for.
    #[error("{} holds {} but no {MARKER} file: it looks like the output of an older `gyrodrift {command}`, which did not mark its folders; pass {flag} to replace it, or delete the folder", path.display(), entries.join(", "))]
    Unmarked {
        /// The folder.
        path: PathBuf,
        /// Its entries, sorted.
        entries: Vec<String>,
        /// The writer's command.
        command: &'static str,
        /// How to ask for replacing.
        flag: &'static str,
    },
    /// The folder holds another command's output.
    #[error("{} holds the output of `gyrodrift {other}`, not of `{command}`: {flag} replaces only a {product}; choose a new folder", path.display())]
    OtherCommand {
        /// The folder.
        path: PathBuf,
        /// The command its marker names.
        other: String,
        /// The writer's command.
        command: &'static str,
        /// What the writer writes.
        product: &'static str,
        /// How replacing is asked for.
        flag: &'static str,
    },
    /// The folder or an earlier output's file could not be read, written or removed.
    #[error("{action} {}: {source}", path.display())]
    Io {
        /// `reading`, `writing`, `renaming` or `removing`.
        action: &'static str,
        /// The path.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

fn io<'a>(action: &'static str, path: &'a Path) -> impl FnOnce(std::io::Error) -> FolderError + 'a {
    move |source| FolderError::Io {
        action,
        path: path.to_owned(),
        source,
    }
}

/// The sorted entries of `out`; `None` if it does not exist.
fn entries(out: &Path) -> Result<Option<Vec<String>>, FolderError> {
    match std::fs::read_dir(out) {
        Ok(entries) => {
            let mut names: Vec<String> = entries
                .filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect();
            names.sort();
            Ok(Some(names))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(source) => Err(FolderError::Io {
            action: "reading",
            path: out.to_owned(),
            source,
        }),
    }
}

/// Checks that `out` may take `writer`'s output: returns `false` if it is missing or empty,
/// `true` if it holds the writer's earlier output and `force` asks to replace it; refuses
/// anything else. Nothing is changed.
pub fn check(
    out: &Path,
    force: bool,
    flag: &'static str,
    writer: &Writer,
) -> Result<bool, FolderError> {
    let Some(entries) = entries(out)? else {
        return Ok(false);
    };
    if entries.is_empty() {
        return Ok(false);
    }
    match writer.owned {
        Owned::Names(names) => {
            let foreign: Vec<String> = entries
                .iter()
                .filter(|name| !names.contains(&name.as_str()))
                .cloned()
                .collect();
            // Without `force` the folder's content is named first: the usual case is a rerun.
            if !foreign.is_empty() && force {
                return Err(FolderError::Foreign {
                    path: out.to_owned(),
                    names: foreign,
                    command: writer.command,
                    product: writer.product,
                    flag,
                });
            }
        }
        Owned::Marker | Owned::MarkerOrNames(_) => {
            let marker = out.join(MARKER);
            let named = std::fs::read_to_string(&marker).ok();
            match named.as_deref().map(str::trim) {
                Some(command) if command == writer.command => {}
                Some(other) => {
                    return Err(FolderError::OtherCommand {
                        path: out.to_owned(),
                        other: other.to_owned(),
                        command: writer.command,
                        product: writer.product,
                        flag,
                    })
                }
                None => match writer.owned {
                    Owned::MarkerOrNames(names)
                        if entries.iter().all(|e| names.contains(&e.as_str())) =>
                    {
                        if !force {
                            return Err(FolderError::Unmarked {
                                path: out.to_owned(),
                                entries,
                                command: writer.command,
                                flag,
                            });
                        }
                    }
                    owned => {
                        let names = match owned {
                            Owned::MarkerOrNames(names) => entries
                                .into_iter()
                                .filter(|e| !names.contains(&e.as_str()))
                                .collect(),
                            _ => entries,
                        };
                        return Err(FolderError::Foreign {
                            path: out.to_owned(),
                            names,
                            command: writer.command,
                            product: writer.product,
                            flag,
                        });
                    }
                },
            }
        }
    }
    if !force {
        return Err(FolderError::NotEmpty {
            path: out.to_owned(),
            entries,
            doing: writer.doing,
            product: writer.product,
            flag,
        });
    }
    Ok(true)
}

/// [`check`], then removes the writer's earlier output from `out` in place (everything in it).
pub fn prepare(
    out: &Path,
    force: bool,
    flag: &'static str,
    writer: &Writer,
) -> Result<(), FolderError> {
    if !check(out, force, flag, writer)? {
        return Ok(());
    }
    for name in entries(out)?.unwrap_or_default() {
        let path = out.join(name);
        let removed = if path.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
        removed.map_err(io("removing", &path))?;
    }
    Ok(())
}

/// A folder beside `out` named after it, for this process: `.<name>.<what>-<pid>`.
fn beside(out: &Path, what: &str) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    out.with_file_name(format!(".{name}.{what}-{}", std::process::id()))
}

/// An output written whole into a temporary folder beside its target and swapped in by
/// [`Staged::commit`]; dropped without a commit, the temporary folder is removed and the target
/// stays as it was.
#[derive(Debug)]
pub struct Staged {
    out: PathBuf,
    stage: PathBuf,
    committed: bool,
}

impl Staged {
    /// [`check`]s `out` for `writer`, then makes the temporary folder with the writer's
    /// [`MARKER`] in it.
    pub fn begin(
        out: &Path,
        force: bool,
        flag: &'static str,
        writer: &Writer,
    ) -> Result<Self, FolderError> {
        check(out, force, flag, writer)?;
        let stage = beside(out, "writing");
        if let Some(parent) = stage.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).map_err(io("writing", parent))?;
        }
        // A leftover of a killed run of this same process id holds nothing worth keeping.
        let _ = std::fs::remove_dir_all(&stage);
        std::fs::create_dir(&stage).map_err(io("writing", &stage))?;
        let staged = Self {
            out: out.to_owned(),
            stage,
            committed: false,
        };
        // A writer known by the names it writes has no marker: one would be foreign to it.
        if matches!(writer.owned, Owned::Marker | Owned::MarkerOrNames(_)) {
            let marker = staged.stage.join(MARKER);
            std::fs::write(&marker, format!("{}\n", writer.command))
                .map_err(io("writing", &marker))?;
        }
        Ok(staged)
    }

    /// The temporary folder to write into.
    pub fn path(&self) -> &Path {
        &self.stage
    }

    /// The target folder.
    pub fn target(&self) -> &Path {
        &self.out
    }

    /// Puts the written output in place of the target (whose earlier content [`check`] allowed
    /// to replace): the earlier output is moved aside, the new one renamed in, the earlier one
    /// removed.
    pub fn commit(mut self) -> Result<(), FolderError> {
        let aside = beside(&self.out, "replaced");
        let earlier = match entries(&self.out)? {
            None => false,
            Some(names) if names.is_empty() => {
                std::fs::remove_dir(&self.out).map_err(io("removing", &self.out))?;
                false
            }
            Some(_) => {
                std::fs::rename(&self.out, &aside).map_err(io("renaming", &self.out))?;
                true
            }
        };
        if let Err(source) = std::fs::rename(&self.stage, &self.out) {
            if earlier {
                // Best effort: put the earlier output back where it was.
                let _ = std::fs::rename(&aside, &self.out);
            }
            return Err(FolderError::Io {
                action: "renaming",
                path: self.stage.clone(),
                source,
            });
        }
        self.committed = true;
        if earlier {
            std::fs::remove_dir_all(&aside).map_err(io("removing", &aside))?;
        }
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            // Best effort: an error path is already being reported.
            let _ = std::fs::remove_dir_all(&self.stage);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FIT: Writer = Writer {
        command: "fit",
        product: "tables folder",
        doing: "fitting",
        owned: Owned::Marker,
    };

    fn staged_write(out: &Path, force: bool, text: &str) -> Result<(), FolderError> {
        let staged = Staged::begin(out, force, "--force", &FIT)?;
        std::fs::write(staged.path().join("a.txt"), text).unwrap();
        staged.commit()
    }

    #[test]
    fn own_output_is_replaced_whole_only_when_forced_and_nothing_else_is_touched() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("tables");
        staged_write(&out, false, "one").unwrap();
        std::fs::write(out.join("stale.txt"), "old").unwrap();
        let error = staged_write(&out, false, "two").unwrap_err().to_string();
        assert!(
            error.contains("pass --force to replace the tables folder"),
            "{error}"
        );
        staged_write(&out, true, "two").unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.txt")).unwrap(), "two");
        assert!(!out.join("stale.txt").exists(), "replaced whole");
        let mut left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["tables"], "no temporary folder left");

        let mine = dir.path().join("mine");
        std::fs::create_dir(&mine).unwrap();
        std::fs::write(mine.join("notes.txt"), "mine").unwrap();
        let error = staged_write(&mine, true, "x").unwrap_err().to_string();
        assert!(
            error.contains("holds files `fit` does not write (notes.txt)"),
            "{error}"
        );
        assert_eq!(
            std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
            "mine"
        );

        std::fs::write(mine.join(MARKER), "report\n").unwrap();
        let error = staged_write(&mine, true, "x").unwrap_err().to_string();
        assert!(
            error.contains("output of `gyrodrift report`, not of `fit`"),
            "{error}"
        );
    }

    #[test]
    fn an_unmarked_folder_of_the_writers_names_is_named_as_an_older_output_and_forced_away() {
        const DEMO: Writer = Writer {
            command: "demo",
            product: "demo",
            doing: "writing the demo",
            owned: Owned::MarkerOrNames(&["campaign", "report"]),
        };
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("demo");
        std::fs::create_dir_all(out.join("campaign")).unwrap();
        std::fs::create_dir_all(out.join("report")).unwrap();
        let error = Staged::begin(&out, false, "--force", &DEMO)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("holds campaign, report but no .gyrodrift-output file: it looks like the output of an older `gyrodrift demo`")
                && error.contains("pass --force to replace it, or delete the folder"),
            "{error}"
        );
        let staged = Staged::begin(&out, true, "--force", &DEMO).unwrap();
        std::fs::create_dir(staged.path().join("report")).unwrap();
        staged.commit().unwrap();
        let mut left: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, [MARKER, "report"], "replaced whole, and marked");

        std::fs::remove_file(out.join(MARKER)).unwrap();
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        let error = Staged::begin(&out, true, "--force", &DEMO)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("holds files `demo` does not write (notes.txt)"),
            "{error}"
        );
    }

    #[test]
    fn a_dropped_stage_leaves_the_target_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("tables");
        staged_write(&out, false, "one").unwrap();
        let staged = Staged::begin(&out, true, "--force", &FIT).unwrap();
        std::fs::write(staged.path().join("a.txt"), "half").unwrap();
        drop(staged);
        assert_eq!(std::fs::read_to_string(out.join("a.txt")).unwrap(), "one");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
