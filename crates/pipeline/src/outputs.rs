//! The checks made on a run's outputs before any work, so that a mistake costs milliseconds, not a
//! measurement, and a run never destroys what it reads: an output is never one of the
//! sample's inputs (compared by [`same_file`]: canonical paths), never written through a link, into
//! another sample's folder or over another sample's results without `force`; its folder exists and
//! is writable. Every failure is an [`OutputError`] whose message names the flag, the path and what
//! to do; nothing here prints or writes (a probe file is created and removed in an output folder).

use std::io;
use std::path::{Path, PathBuf};

pub use scatterfit_io::inputs::same_file;
use scatterfit_io::{atomic, escape, manifest, result_set};

/// The files a measurement writes into a sample's output folder
/// (`scatterfit_report::write_measurement`, `report.html` being its `html::SAMPLE_PAGE`, which a
/// report test checks is listed here), the set manifest last.
pub const RESULT_FILES: [&str; 8] = [
    "profile.csv",
    "result.json",
    "result.csv",
    "result.md",
    "fit.svg",
    "fit.png",
    "report.html",
    result_set::SET_FILE,
];

/// Samples that were not measured, with the reason: `(folder, why)`.
pub type Failures = Vec<(PathBuf, String)>;

/// An output refused before any work.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// A command's output is one of the sample's inputs.
    #[error(
        "{} would be written by `{command}`, but it is an input of the sample ({key}: {}); inputs \
         are never overwritten and nothing was written — rename the input (and where it is named) \
         or write the results elsewhere with -o DIR",
        output.display(),
        input.display()
    )]
    OutputIsInput {
        /// The command (`measure`, `batch`, …).
        command: String,
        /// The output.
        output: PathBuf,
        /// Where the input is named (`spectro.file`, `camera.images`, …).
        key: String,
        /// The input.
        input: PathBuf,
    },
    /// An output file given on the command line is also an input.
    #[error(
        "{what} {} is also an input ({}); inputs are never overwritten — choose another output file",
        output.display(),
        input.display()
    )]
    OverwritesInput {
        /// The flag or role of the output (`-o`).
        what: String,
        /// The output.
        output: PathBuf,
        /// The input.
        input: PathBuf,
    },
    /// `-o` names the folder of another sample.
    #[error(
        "-o {}: this is the folder of another sample (it holds {}); its result files would be \
         replaced by this sample's and nothing was written — choose another folder, or pass \
         --force if you mean it",
        out.display(),
        manifest::MANIFEST_NAME
    )]
    AnotherSampleFolder {
        /// The output folder.
        out: PathBuf,
    },
    /// `-o` holds result files that are not this sample's.
    #[error(
        "-o {} holds {what}: {}; nothing was written — pass --force to replace them, or choose \
         another folder",
        out.display(),
        present.join(", ")
    )]
    ForeignResults {
        /// The output folder.
        out: PathBuf,
        /// Whose results they are, as far as can be told.
        what: String,
        /// The result files present.
        present: Vec<String>,
    },
    /// The output file's extension does not match what is written.
    #[error(
        "{flag} {}: {what}; name the file {} (e.g. `{}`)",
        path.display(),
        extensions.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(" or "),
        path.with_extension(extensions[0]).display()
    )]
    Extension {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
        /// What is written into it.
        what: &'static str,
        /// The accepted extensions (non-empty).
        extensions: &'static [&'static str],
    },
    /// The output file is a folder.
    #[error("{flag} {}: is a folder; name a file", path.display())]
    IsFolder {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
    },
    /// The output file exists and `force` was not given.
    #[error(
        "{flag} {}: the file exists; nothing was done — pass --force to replace it, or choose \
         another name",
        path.display()
    )]
    Exists {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
    },
    /// The output is a link, or exists and is not a regular file.
    #[error("{flag} {}: {source}", path.display())]
    Destination {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
        /// What it is.
        source: io::Error,
    },
    /// The output's folder (or the nearest existing folder above an output folder) is not a
    /// folder.
    #[error("{flag} {}: {} is not a folder; choose another output {kind}", path.display(), folder.display())]
    NotAFolder {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
        /// The folder that is not one.
        folder: PathBuf,
        /// `file` or `folder`.
        kind: &'static str,
    },
    /// The output file's folder does not exist.
    #[error("{flag} {}: the folder {} does not exist; create it first", path.display(), folder.display())]
    NoFolder {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
        /// The missing folder.
        folder: PathBuf,
    },
    /// The folder cannot be written in.
    #[error(
        "{flag} {}: cannot write in {} ({source}); choose a writable folder",
        path.display(),
        folder.display()
    )]
    NotWritable {
        /// The flag.
        flag: String,
        /// The output.
        path: PathBuf,
        /// The folder.
        folder: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// A file a command writes into an output folder exists and `force` was not given.
    #[error(
        "{} already exists; nothing was written — choose another folder or pass --force to \
         overwrite",
        path.display()
    )]
    InFolderExists {
        /// The file.
        path: PathBuf,
    },
    /// A command's own folder (`--output-dir` of the demo, the study) holds files it did not make.
    #[error(
        "{} holds {holds} and was not made by `scatterfit {command}`; choose another folder with -o \
         or pass --force{hint}",
        dir.display()
    )]
    NotOwnFolder {
        /// The folder.
        dir: PathBuf,
        /// The first entry found there.
        holds: String,
        /// The command that owns its folders.
        command: &'static str,
        /// What `--force` does, after "pass --force" (e.g. " to write there"), or empty.
        hint: &'static str,
    },
    /// A folder could not be read or made, or a file in it written.
    #[error("{action} {}", path.display())]
    Folder {
        /// `reading`, `creating`, `writing`.
        action: &'static str,
        /// The folder or file.
        path: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// A refusal concerning one sample of many.
    #[error("sample {}", dir.display())]
    Sample {
        /// The sample folder.
        dir: PathBuf,
        /// The refusal.
        #[source]
        source: Box<OutputError>,
    },
}

/// What an output file must be: its extensions and, for messages, what is written into it.
#[derive(Debug, Clone, Copy)]
pub struct Format {
    /// Accepted extensions, lower case without the dot; the first is suggested.
    pub extensions: &'static [&'static str],
    /// What the command writes, e.g. "the profile is CSV".
    pub what: &'static str,
}

/// Refuses to let `command` write any of `outputs` over one of the sample's `inputs` (compared by
/// [`same_file`]): a spectro file called `result.csv`, a frame called `fit.png` would be destroyed
/// by the run that reads them.
///
/// # Errors
/// [`OutputError::OutputIsInput`], naming the output, the input and where the input is named.
pub fn refuse_outputs_that_are_inputs(
    command: &str,
    outputs: &[PathBuf],
    inputs: &[(String, PathBuf)],
) -> Result<(), OutputError> {
    for out in outputs {
        if let Some((key, input)) = inputs.iter().find(|(_, i)| same_file(i, out)) {
            return Err(OutputError::OutputIsInput {
                command: command.to_owned(),
                output: out.clone(),
                key: key.clone(),
                input: input.clone(),
            });
        }
    }
    Ok(())
}

/// `measure A -o B`: refuses, unless `force`, to write into a folder `out` that is not the sample's
/// own (`sample_dir`) when it is another sample's folder (it holds a `sample.toml`) or holds result
/// files that are not this sample's (their `result-files.json` names another sample, or there is
/// none to tell). This sample's earlier results there are replaced.
///
/// # Errors
/// [`OutputError::AnotherSampleFolder`], [`OutputError::ForeignResults`].
pub fn refuse_foreign_results(
    sample_dir: &Path,
    out: &Path,
    force: bool,
) -> Result<(), OutputError> {
    if force || !out.is_dir() || same_file(out, sample_dir) {
        return Ok(());
    }
    if std::fs::symlink_metadata(out.join(manifest::MANIFEST_NAME)).is_ok() {
        return Err(OutputError::AnotherSampleFolder {
            out: out.to_path_buf(),
        });
    }
    let present: Vec<String> = RESULT_FILES
        .iter()
        .filter(|f| std::fs::symlink_metadata(out.join(f)).is_ok())
        .map(|f| (*f).to_owned())
        .collect();
    if present.is_empty() {
        return Ok(());
    }
    let what = match result_set::read(out) {
        Ok(Some(set)) if same_file(Path::new(&set.sample_dir), sample_dir) => return Ok(()),
        Ok(Some(set)) => format!(
            "the results of the sample {} (measured from {}, run {})",
            escape::token(&set.sample),
            escape::one_line(&set.sample_dir),
            escape::token(&set.run_id)
        ),
        Ok(None) => format!(
            "result files that cannot be tied to this sample (no {}: written by another sample, an \
             older scatterfit or an interrupted run)",
            result_set::SET_FILE
        ),
        Err(e) => format!("result files with an unreadable set manifest ({e})"),
    };
    Err(OutputError::ForeignResults {
        out: out.to_path_buf(),
        what,
        present,
    })
}

/// The sample folders of a run over many samples (`batch`, `compare`), found and checked before any
/// work.
#[derive(Debug)]
pub struct CheckedSamples {
    /// Each folder once ([`crate::sample_dirs`]).
    pub dirs: Vec<PathBuf>,
    /// Other spellings of a folder in `dirs`: `(path, the one kept)` (a caller may note them).
    pub duplicates: Vec<(PathBuf, PathBuf)>,
    /// Folders whose manifest is misspelt, with the message to report; not measured.
    pub misspelt: Failures,
}

/// Finds the sample folders of `dirs` ([`crate::sample_dirs`]) and checks, before any work, every
/// sample's `per_sample` outputs (in its own folder) and the run's `shared` outputs against every
/// sample's inputs. A sample whose manifest cannot be read is kept: it fails later with its own
/// error, like any other.
///
/// # Errors
/// An output that is an input ([`OutputError::Sample`] around [`OutputError::OutputIsInput`]), or a
/// link at an output's name ([`OutputError::Destination`]).
pub fn check_samples(
    command: &str,
    dirs: &[PathBuf],
    per_sample: &[&str],
    shared: &[PathBuf],
    allow_outside: bool,
) -> Result<CheckedSamples, OutputError> {
    let found = crate::sample_dirs(dirs);
    let mut misspelt: Failures = found
        .misspelt
        .iter()
        .map(|(dir, file)| {
            (
                dir.clone(),
                format!(
                    "no sample.toml, but {} — rename it to exactly sample.toml (names are \
                     case-sensitive); not measured",
                    escape::token(&file.file_name().unwrap_or_default().to_string_lossy())
                ),
            )
        })
        .collect();
    misspelt.extend(found.links_out.iter().map(|(link, top)| {
        (
            link.clone(),
            format!(
                "a symbolic link that leads out of {}; not measured — a folder of samples is \
                 never left through a link (its results would be written where the link points); \
                 give the sample folder itself if you mean it",
                top.display()
            ),
        )
    }));
    for o in shared {
        check_destination(o, "-o")?;
    }
    for dir in &found.dirs {
        let Ok(inputs) = crate::sample_inputs(dir, allow_outside) else {
            continue;
        };
        let mut outputs: Vec<PathBuf> = per_sample.iter().map(|f| dir.join(f)).collect();
        for o in &outputs {
            check_destination(o, "-o")?;
        }
        outputs.extend(shared.iter().cloned());
        refuse_outputs_that_are_inputs(command, &outputs, &inputs.files).map_err(|e| {
            OutputError::Sample {
                dir: dir.clone(),
                source: Box::new(e),
            }
        })?;
    }
    Ok(CheckedSamples {
        dirs: found.dirs,
        duplicates: found.duplicates,
        misspelt,
    })
}

/// `batch`/`compare -o DIR`: refuses, unless `force`, a `DIR` that is the folder of a sample not
/// being measured (it holds a `sample.toml`): its files are that sample's.
///
/// # Errors
/// [`OutputError::AnotherSampleFolder`].
pub fn refuse_foreign_folder(
    out: &Path,
    measured: &[PathBuf],
    force: bool,
) -> Result<(), OutputError> {
    let out = if out.as_os_str().is_empty() {
        Path::new(".")
    } else {
        out
    };
    if force
        || std::fs::symlink_metadata(out.join(manifest::MANIFEST_NAME)).is_err()
        || measured.iter().any(|d| same_file(d, out))
    {
        return Ok(());
    }
    Err(OutputError::AnotherSampleFolder {
        out: out.to_path_buf(),
    })
}

/// Refuses to write `output` over any of `inputs`.
///
/// # Errors
/// [`OutputError::OverwritesInput`].
pub fn refuse_overwrite(output: &Path, what: &str, inputs: &[&Path]) -> Result<(), OutputError> {
    match inputs.iter().find(|i| same_file(i, output)) {
        Some(input) => Err(OutputError::OverwritesInput {
            what: what.to_owned(),
            output: output.to_path_buf(),
            input: input.to_path_buf(),
        }),
        None => Ok(()),
    }
}

/// Checks an output file: the extension matches what is written, the path is not one of the
/// `inputs`, not a folder, not an existing file unless `force`, and its folder exists and is
/// writable (a probe file is created and removed there).
///
/// # Errors
/// The first problem, naming `flag` and the path and saying what to do.
pub fn check_output_file(
    path: &Path,
    flag: &str,
    format: Format,
    inputs: &[&Path],
    force: bool,
) -> Result<(), OutputError> {
    refuse_overwrite(path, flag, inputs)?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !format.extensions.iter().any(|e| ext.as_deref() == Some(*e)) {
        return Err(OutputError::Extension {
            flag: flag.to_owned(),
            path: path.to_path_buf(),
            what: format.what,
            extensions: format.extensions,
        });
    }
    let err = |make: fn(String, PathBuf) -> OutputError| Err(make(flag.to_owned(), path.into()));
    if path.is_dir() {
        return err(|flag, path| OutputError::IsFolder { flag, path });
    }
    check_destination(path, flag)?;
    if path.exists() && !force {
        return err(|flag, path| OutputError::Exists { flag, path });
    }
    check_output_folder(path, flag)
}

/// Checks an output file whose extension the caller has checked (`render -o`, repeatable): not a
/// link or non-file, not an existing file unless `force`, not one of the `inputs`, not a folder,
/// and its folder exists and is writable.
///
/// # Errors
/// The first problem, naming `flag` and the path and saying what to do.
pub fn check_new_output(
    path: &Path,
    flag: &str,
    inputs: &[&Path],
    force: bool,
) -> Result<(), OutputError> {
    check_destination(path, flag)?;
    let err = |make: fn(String, PathBuf) -> OutputError| Err(make(flag.to_owned(), path.into()));
    if path.exists() && !force {
        return err(|flag, path| OutputError::Exists { flag, path });
    }
    refuse_overwrite(path, flag, inputs)?;
    if path.is_dir() {
        return err(|flag, path| OutputError::IsFolder { flag, path });
    }
    check_output_folder(path, flag)
}

/// Refuses an output path that is a symbolic link (even a dangling one) or exists and is not a
/// regular file: writes never go through a link (`scatterfit_io::atomic`), and saying so before the
/// work saves it.
///
/// # Errors
/// [`OutputError::Destination`].
pub fn check_destination(path: &Path, flag: &str) -> Result<(), OutputError> {
    atomic::check_destination(path).map_err(|source| OutputError::Destination {
        flag: flag.to_owned(),
        path: path.to_path_buf(),
        source,
    })
}

/// Checks that the folder of the output file `path` exists and is writable (a probe file is
/// created and removed there).
///
/// # Errors
/// [`OutputError::NotAFolder`], [`OutputError::NoFolder`], [`OutputError::NotWritable`].
pub fn check_output_folder(path: &Path, flag: &str) -> Result<(), OutputError> {
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if folder.exists() && !folder.is_dir() {
        return Err(OutputError::NotAFolder {
            flag: flag.to_owned(),
            path: path.to_path_buf(),
            folder: folder.to_path_buf(),
            kind: "file",
        });
    }
    if !folder.is_dir() {
        return Err(OutputError::NoFolder {
            flag: flag.to_owned(),
            path: path.to_path_buf(),
            folder: folder.to_path_buf(),
        });
    }
    writable(path, folder, flag)
}

/// Checks an output folder: an existing one must be a writable folder; a new one is created later,
/// so the nearest folder above it that exists must be writable.
///
/// # Errors
/// [`OutputError::NotAFolder`], [`OutputError::NotWritable`].
pub fn check_output_dir(dir: &Path, flag: &str) -> Result<(), OutputError> {
    let mut probe = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    while !probe.exists() {
        match probe.parent() {
            Some(p) if !p.as_os_str().is_empty() => probe = p,
            _ => {
                probe = Path::new(".");
                break;
            }
        }
    }
    if !probe.is_dir() {
        return Err(OutputError::NotAFolder {
            flag: flag.to_owned(),
            path: dir.to_path_buf(),
            folder: probe.to_path_buf(),
            kind: "folder",
        });
    }
    writable(dir, probe, flag)
}

/// Refuses to write `files` into `dir` when any of them already exists there, unless `force`; a
/// link or a non-file at one of their names always (`-o`).
///
/// # Errors
/// [`OutputError::Destination`]; [`OutputError::InFolderExists`], naming the first file that
/// exists.
pub fn check_output_files(dir: &Path, files: &[String], force: bool) -> Result<(), OutputError> {
    for f in files {
        check_destination(&dir.join(f), "-o")?;
    }
    match files
        .iter()
        .map(|f| dir.join(f))
        .find(|p| !force && p.exists())
    {
        Some(path) => Err(OutputError::InFolderExists { path }),
        None => Ok(()),
    }
}

/// Takes `dir` as the folder of `command` (the demo, the study), which replaces its own files
/// there on every run: a folder is the command's when it is new, empty or holds the command's
/// `marker` file; another is refused unless `force` (`hint` says what `--force` does, for the
/// message). Then the folder is created and the marker written into it.
///
/// # Errors
/// [`OutputError::NotOwnFolder`], naming the first entry found; [`OutputError::Folder`] when the
/// folder cannot be read or made or the marker written.
pub fn claim_folder(
    dir: &Path,
    marker: &str,
    command: &'static str,
    hint: &'static str,
    force: bool,
) -> Result<(), OutputError> {
    let failed = |action, path: &Path| {
        let path = path.to_path_buf();
        move |source| OutputError::Folder {
            action,
            path,
            source,
        }
    };
    if dir.exists() && !force && !dir.join(marker).exists() {
        let mut entries = std::fs::read_dir(dir)
            .map_err(failed("reading", dir))?
            .flatten();
        if let Some(e) = entries.next() {
            return Err(OutputError::NotOwnFolder {
                dir: dir.to_path_buf(),
                holds: e.file_name().to_string_lossy().into_owned(),
                command,
                hint,
            });
        }
    }
    std::fs::create_dir_all(dir).map_err(failed("creating", dir))?;
    let marker = dir.join(marker);
    let text = format!("made by `scatterfit {command}`; it may replace the files in this folder\n");
    atomic::write_atomic(&marker, text.as_bytes()).map_err(failed("writing", &marker))
}

fn writable(path: &Path, folder: &Path, flag: &str) -> Result<(), OutputError> {
    atomic::check_can_write_in(folder).map_err(|source| OutputError::NotWritable {
        flag: flag.to_owned(),
        path: path.to_path_buf(),
        folder: folder.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each refusal, and its message naming the flag, the path and what to do.
    #[test]
    fn refusals_name_the_path_and_what_to_do() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("spectro.csv");
        std::fs::write(&input, "x").unwrap();
        let csv = Format {
            extensions: &["csv"],
            what: "the profile is CSV",
        };
        let e = check_output_file(&input, "-o", csv, &[input.as_path()], true).unwrap_err();
        assert!(e.to_string().contains("is also an input"), "{e}");
        let png = dir.path().join("p.png");
        let e = check_output_file(&png, "-o", csv, &[], false).unwrap_err();
        assert!(e.to_string().contains("name the file .csv (e.g. `"), "{e}");
        let e = check_output_file(&input, "-o", csv, &[], false).unwrap_err();
        assert!(matches!(e, OutputError::Exists { .. }), "{e}");
        assert!(check_output_file(&input, "-o", csv, &[], true).is_ok());
        let missing = dir.path().join("none/p.csv");
        let e = check_output_file(&missing, "-o", csv, &[], false).unwrap_err();
        assert!(
            e.to_string().contains("does not exist; create it first"),
            "{e}"
        );
        let e = check_output_dir(&input.join("sub"), "-o").unwrap_err();
        assert!(e.to_string().contains("is not a folder"), "{e}");
        assert!(check_output_dir(&dir.path().join("new/deeper"), "-o").is_ok());
    }

    /// Another sample's folder and results that cannot be tied to this sample are refused unless
    /// forced; this sample's own folder never is.
    #[test]
    fn foreign_results_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (mine, other) = (dir.path().join("mine"), dir.path().join("other"));
        std::fs::create_dir_all(&mine).unwrap();
        std::fs::create_dir_all(&other).unwrap();
        assert!(refuse_foreign_results(&mine, &other, false).is_ok());
        std::fs::write(other.join("result.json"), "{}").unwrap();
        let e = refuse_foreign_results(&mine, &other, false).unwrap_err();
        assert!(
            e.to_string().contains("cannot be tied to this sample"),
            "{e}"
        );
        assert!(refuse_foreign_results(&mine, &other, true).is_ok());
        assert!(refuse_foreign_results(&other, &other, false).is_ok());
        std::fs::write(other.join(manifest::MANIFEST_NAME), "").unwrap();
        let e = refuse_foreign_results(&mine, &other, false).unwrap_err();
        assert!(matches!(e, OutputError::AnotherSampleFolder { .. }), "{e}");
    }
}
