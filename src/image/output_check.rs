//! Every file a command writes is checked here, together, before any work starts: a bad output
//! must cost the user nothing (exit code 2 up front, not an error after an hour's render), and
//! no output may silently replace another output or one of the command's inputs.
//!
//! Use it in every command that writes files, with every output and every input it has:
//!
//! ```ignore
//! OutputSet::new()
//!     .input("the scene", &args.scene)
//!     .image("-o", &output)              // .png or .exr
//!     .exr("--variance", &variance)      // .exr only
//!     .file("--raw", &raw)               // any format the command writes itself
//!     .check()?;                         // Err(InputError): exit code 2
//! ```
//!
//! [`OutputSet::check`] refuses, with a one-line message naming the flag and the file:
//! - an image output whose extension is not a format glint writes;
//! - an output whose folder does not exist, that is a folder, or that exists but is not a
//!   regular file (a device, a FIFO: `/dev/stdout`, `/proc/…`);
//! - an output in a folder where glint cannot create a file (read-only, `/proc`): probed by
//!   creating and removing a temporary file there, as [`crate::image::atomic_write`] will;
//! - two outputs that are the same file, and an output that is one of the inputs. Paths are
//!   compared after resolving symbolic links and `..` (an output that does not exist yet is its
//!   resolved folder plus its name) and, for files that exist, by device and inode, so hard
//!   links count too.

use crate::error::InputError;
use crate::image::format::ImageFormat;
use std::fs::Metadata;
use std::io;
use std::path::{Path, PathBuf};

/// Symbolic links followed at most when resolving a dangling link, as the kernel's limit.
const MAX_LINK_DEPTH: usize = 40;

/// What an output must be named like.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// A .png or .exr image.
    Image,
    /// An .exr image (linear floats).
    Exr,
    /// Any file; its format is the caller's business.
    File,
}

#[derive(Clone, Debug)]
struct Named {
    /// The flag or argument that named the file (`-o`, `--variance`, `the scene`).
    what: String,
    path: PathBuf,
    kind: Kind,
}

/// The files one command reads and writes; see the module documentation.
#[derive(Clone, Debug, Default)]
#[must_use = "nothing is checked until .check()"]
pub struct OutputSet {
    inputs: Vec<Named>,
    outputs: Vec<Named>,
}

/// Where an output will really be written.
struct Target {
    /// Absolute, with links and `..` resolved.
    path: PathBuf,
    /// Device and inode, when the file exists.
    id: Option<(u64, u64)>,
}

impl OutputSet {
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// A file the command reads: no output may be it. An input that cannot be resolved (it
    /// does not exist) is left to the code that reads it to report.
    pub fn input(mut self, what: &str, path: &Path) -> OutputSet {
        self.inputs.push(Named {
            what: what.into(),
            path: path.into(),
            kind: Kind::File,
        });
        self
    }

    /// The same, for an optional flag.
    pub fn input_opt(self, what: &str, path: Option<&Path>) -> OutputSet {
        match path {
            Some(p) => self.input(what, p),
            None => self,
        }
    }

    /// An image output: .png or .exr.
    pub fn image(self, what: &str, path: &Path) -> OutputSet {
        self.add(what, path, Kind::Image)
    }

    /// A linear image output: .exr only.
    pub fn exr(self, what: &str, path: &Path) -> OutputSet {
        self.add(what, path, Kind::Exr)
    }

    /// An output of any format (the caller checks the name if it cares).
    pub fn file(self, what: &str, path: &Path) -> OutputSet {
        self.add(what, path, Kind::File)
    }

    /// The same, for an optional flag.
    pub fn image_opt(self, what: &str, path: Option<&Path>) -> OutputSet {
        match path {
            Some(p) => self.image(what, p),
            None => self,
        }
    }

    /// The same, for an optional flag.
    pub fn exr_opt(self, what: &str, path: Option<&Path>) -> OutputSet {
        match path {
            Some(p) => self.exr(what, p),
            None => self,
        }
    }

    fn add(mut self, what: &str, path: &Path, kind: Kind) -> OutputSet {
        self.outputs.push(Named {
            what: what.into(),
            path: path.into(),
            kind,
        });
        self
    }

    /// Checks every output as the module documentation says; the first problem is the error.
    pub fn check(&self) -> Result<(), InputError> {
        let mut targets: Vec<(&Named, Target)> = Vec::new();
        for output in &self.outputs {
            let target = check_one(output).map_err(InputError)?;
            if let Some((other, _)) = targets.iter().find(|(_, t)| same_file(t, &target)) {
                return Err(InputError(format!(
                    "{} {} and {} {} are the same file; each output needs its own",
                    other.what,
                    other.path.display(),
                    output.what,
                    output.path.display()
                )));
            }
            for input in &self.inputs {
                let Ok(input_target) = resolve_existing(&input.path) else {
                    continue;
                };
                if same_file(&input_target, &target) {
                    return Err(InputError(format!(
                        "{} {} is {} ({}); writing it would destroy an input",
                        output.what,
                        output.path.display(),
                        input.what,
                        input.path.display()
                    )));
                }
            }
            targets.push((output, target));
        }
        Ok(())
    }
}

fn same_file(a: &Target, b: &Target) -> bool {
    a.path == b.path || (a.id.is_some() && a.id == b.id)
}

#[cfg(unix)]
fn file_id(meta: &Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn file_id(_meta: &Metadata) -> Option<(u64, u64)> {
    None
}

fn resolve_existing(path: &Path) -> io::Result<Target> {
    let resolved = std::fs::canonicalize(path)?;
    let meta = std::fs::metadata(&resolved)?;
    Ok(Target {
        path: resolved,
        id: file_id(&meta),
    })
}

/// The file a write to `path` lands in: a symbolic link's final target (which may not exist
/// yet), else `path` itself; absolute, with links and `..` resolved in its folder. Shared with
/// [`crate::image::atomic_write`], which writes the temporary file next to this target.
pub fn resolve_output_target(path: &Path) -> Result<PathBuf, String> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINK_DEPTH {
        match std::fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&current)
                    .map_err(|e| format!("{}: cannot read the link: {e}", path.display()))?;
                current = match current.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return resolve_in_folder(path, &current),
        }
    }
    Err(format!(
        "{}: too many levels of symbolic links",
        path.display()
    ))
}

/// `file` (not a link) with its folder resolved; `named` is what the user wrote, for messages.
fn resolve_in_folder(named: &Path, file: &Path) -> Result<PathBuf, String> {
    let name = file
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", named.display()))?;
    let folder = match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let folder = std::fs::canonicalize(folder).map_err(|e| {
        if e.kind() == io::ErrorKind::NotFound {
            format!(
                "{}: the output folder {} does not exist",
                named.display(),
                folder.display()
            )
        } else {
            format!(
                "{}: the output folder {} cannot be used: {e}",
                named.display(),
                folder.display()
            )
        }
    })?;
    if !folder.is_dir() {
        return Err(format!(
            "{}: {} is not a folder",
            named.display(),
            folder.display()
        ));
    }
    Ok(folder.join(name))
}

fn check_one(output: &Named) -> Result<Target, String> {
    let path = &output.path;
    let shown = || format!("{} {}", output.what, path.display());
    match output.kind {
        Kind::Image => {
            ImageFormat::from_path(path).map_err(|m| format!("{}: {m}", output.what))?;
        }
        Kind::Exr => {
            if ImageFormat::from_path(path) != Ok(ImageFormat::Exr) {
                return Err(format!(
                    "{}: needs an .exr file name (linear floats)",
                    shown()
                ));
            }
        }
        Kind::File => {}
    }
    let resolved = resolve_output_target(path).map_err(|m| format!("{}: {m}", output.what))?;
    let mut id = None;
    match std::fs::metadata(&resolved) {
        Ok(meta) if meta.is_dir() => return Err(format!("{}: is a folder", shown())),
        Ok(meta) if !meta.is_file() => {
            return Err(format!(
                "{}: exists and is not a regular file (a device, FIFO or socket); glint writes files by replacing them",
                shown()
            ))
        }
        Ok(meta) => id = file_id(&meta),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(format!("{}: {e}", shown())),
    }
    let folder = resolved.parent().unwrap_or(Path::new("/"));
    // The write creates a temporary file there and renames it: try exactly that now.
    tempfile::Builder::new()
        .prefix(".glint-")
        .suffix(".tmp")
        .tempfile_in(folder)
        .map_err(|e| {
            format!(
                "{}: cannot create files in {}: {e}",
                shown(),
                folder.display()
            )
        })?;
    Ok(Target { path: resolved, id })
}
