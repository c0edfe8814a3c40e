//! Denoising with Intel Open Image Denoise (OIDN 2), loaded at run time.
//!
//! Why by hand, and at run time: the `oidn` crate links the library when glint is built (its
//! `bundled` feature downloads it, which offline machines cannot), so glint would not build
//! without OIDN installed. Loading `libOpenImageDenoise` with `libloading` keeps the renderer
//! building and running everywhere; only `--denoise` (and the viewer's D key) need the library.
//! The few functions used here are OIDN 2's stable C API (`OpenImageDenoise/oidn.h`).
//!
//! Where the library is looked for, first found wins:
//! 1. `GLINT_OIDN_LIB`: the library file itself (then nothing else is tried);
//! 2. `OIDN_DIR`: an OIDN install (its `lib/`), or the folder holding the library;
//! 3. the PyPI package `pyoidn` (`pip install pyoidn`), which ships the library: asked of
//!    `python3`, then looked for in the usual site-packages folders;
//! 4. the system's library path (`libOpenImageDenoise.so.2`).

use crate::image::aov::Aovs;
use crate::image::output::Image;
use anyhow::{anyhow, Result};
use std::ffi::{c_char, c_void, CStr};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The one install step, for error messages and the README.
pub const INSTALL_HINT: &str =
    "install it with `pip install pyoidn` (or set GLINT_OIDN_LIB to libOpenImageDenoise.so)";

#[cfg(target_os = "linux")]
const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];
#[cfg(target_os = "macos")]
const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"];
#[cfg(windows)]
const LIBRARY_NAMES: &[&str] = &["OpenImageDenoise.dll"];

type Device = *mut c_void;
type Filter = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU`: glint's images live in host memory.
const DEVICE_TYPE_CPU: i32 = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: i32 = 3;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: i32 = 0;

/// The OIDN functions glint calls, resolved from the loaded library.
pub struct Oidn {
    new_device: unsafe extern "C" fn(i32) -> Device,
    commit_device: unsafe extern "C" fn(Device),
    release_device: unsafe extern "C" fn(Device),
    get_device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> i32,
    new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    #[allow(clippy::type_complexity)]
    set_shared_filter_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        *mut c_void,
        i32,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    commit_filter: unsafe extern "C" fn(Filter),
    execute_filter: unsafe extern "C" fn(Filter),
    release_filter: unsafe extern "C" fn(Filter),
    /// Where the library was found.
    pub path: PathBuf,
    /// Keeps the functions above valid.
    _library: libloading::Library,
}

/// The library paths to try, in order (see the module documentation).
fn candidates() -> Vec<PathBuf> {
    // An explicit file is the only place looked, so a wrong one is reported, not bypassed.
    if let Some(file) = std::env::var_os("GLINT_OIDN_LIB") {
        return vec![PathBuf::from(file)];
    }
    let mut out = Vec::new();
    let in_folder = |dir: &Path, out: &mut Vec<PathBuf>| {
        for name in LIBRARY_NAMES {
            out.push(dir.join(name));
        }
    };
    if let Some(dir) = std::env::var_os("OIDN_DIR") {
        let dir = PathBuf::from(dir);
        in_folder(&dir.join("lib"), &mut out);
        in_folder(&dir, &mut out);
    }
    for package in pyoidn_folders() {
        in_folder(&package.join("oidn").join("lib"), &mut out);
    }
    // Bare names: the dynamic loader's own search (LD_LIBRARY_PATH, ld.so.cache).
    out.extend(LIBRARY_NAMES.iter().map(PathBuf::from));
    out
}

/// Folders where the `pyoidn` package may be installed.
fn pyoidn_folders() -> Vec<PathBuf> {
    let mut out = Vec::new();
    // The interpreter on PATH knows where pip put it (virtual environments, pyenv, --user).
    let asked = std::process::Command::new("python3")
        .args([
            "-c",
            "import importlib.util as u; s = u.find_spec('pyoidn'); print(s.submodule_search_locations[0] if s else '')",
        ])
        .stderr(std::process::Stdio::null())
        .output();
    if let Ok(out_bytes) = asked {
        let text = String::from_utf8_lossy(&out_bytes.stdout)
            .trim()
            .to_string();
        if !text.is_empty() {
            out.push(PathBuf::from(text));
        }
    }
    let mut roots = vec![PathBuf::from("/usr/local/lib"), PathBuf::from("/usr/lib")];
    if let Some(home) = std::env::var_os("HOME") {
        roots.push(Path::new(&home).join(".local/lib"));
    }
    for root in roots {
        let Ok(entries) = std::fs::read_dir(&root) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            if name.to_string_lossy().starts_with("python3") {
                for packages in ["site-packages", "dist-packages"] {
                    out.push(entry.path().join(packages).join("pyoidn"));
                }
            }
        }
    }
    out
}

/// The library, loaded once per process; the error says how to install it.
pub fn oidn() -> Result<&'static Oidn> {
    static OIDN: OnceLock<Result<Oidn, String>> = OnceLock::new();
    OIDN.get_or_init(load).as_ref().map_err(|e| anyhow!("{e}"))
}

fn load() -> Result<Oidn, String> {
    for path in candidates() {
        let is_bare_name = path.components().count() == 1;
        if !is_bare_name && !path.is_file() {
            continue;
        }
        // SAFETY: loading OIDN runs its initialisers, which only set up its own state.
        let Ok(library) = (unsafe { libloading::Library::new(&path) }) else {
            continue;
        };
        let shown = path.display().to_string();
        return Oidn::resolve(library, path)
            .map_err(|e| format!("{shown} is not a usable Open Image Denoise 2: {e}"));
    }
    if let Some(file) = std::env::var_os("GLINT_OIDN_LIB") {
        return Err(format!(
            "denoising needs Intel Open Image Denoise 2, and GLINT_OIDN_LIB={} cannot be loaded; {INSTALL_HINT}",
            Path::new(&file).display()
        ));
    }
    Err(format!(
        "denoising needs Intel Open Image Denoise 2, which was not found; {INSTALL_HINT}"
    ))
}

impl Oidn {
    fn resolve(library: libloading::Library, path: PathBuf) -> Result<Oidn, libloading::Error> {
        // SAFETY: each symbol is declared with its signature in OIDN 2's oidn.h.
        unsafe {
            Ok(Oidn {
                new_device: *library.get(b"oidnNewDevice\0")?,
                commit_device: *library.get(b"oidnCommitDevice\0")?,
                release_device: *library.get(b"oidnReleaseDevice\0")?,
                get_device_error: *library.get(b"oidnGetDeviceError\0")?,
                new_filter: *library.get(b"oidnNewFilter\0")?,
                set_shared_filter_image: *library.get(b"oidnSetSharedFilterImage\0")?,
                set_filter_bool: *library.get(b"oidnSetFilterBool\0")?,
                commit_filter: *library.get(b"oidnCommitFilter\0")?,
                execute_filter: *library.get(b"oidnExecuteFilter\0")?,
                release_filter: *library.get(b"oidnReleaseFilter\0")?,
                path,
                _library: library,
            })
        }
    }

    /// Denoises `color` (linear HDR radiance) with the `RT` filter, guided by the albedo and
    /// normal AOVs, which are first denoised themselves so the main filter can trust them
    /// (`cleanAux`), as OIDN's documentation recommends for noisy auxiliary images.
    pub fn denoise(&self, color: &Image, aovs: &Aovs) -> Result<Image> {
        let (width, height) = (color.width as usize, color.height as usize);
        for aux in [&aovs.albedo, &aovs.normal] {
            if (aux.width, aux.height) != (color.width, color.height) {
                return Err(anyhow!("the AOVs' size differs from the image's"));
            }
        }
        let device = DeviceGuard::new(self)?;
        let mut albedo = aovs.albedo.pixels.clone();
        let mut normal = aovs.normal.pixels.clone();
        // Prefilter each auxiliary image in place: an RT filter with only that input.
        for (name, pixels) in [(c"albedo", &mut albedo), (c"normal", &mut normal)] {
            let filter = device.filter()?;
            let ptr = pixels.as_mut_ptr() as *mut c_void;
            filter.image(name, ptr, width, height);
            filter.image(c"output", ptr, width, height);
            filter.run()?;
        }
        let mut input = color.pixels.clone();
        let mut output = vec![[0.0f32; 3]; input.len()];
        let filter = device.filter()?;
        filter.image(c"color", input.as_mut_ptr() as *mut c_void, width, height);
        filter.image(c"albedo", albedo.as_mut_ptr() as *mut c_void, width, height);
        filter.image(c"normal", normal.as_mut_ptr() as *mut c_void, width, height);
        filter.image(c"output", output.as_mut_ptr() as *mut c_void, width, height);
        filter.flag(c"hdr", true);
        filter.flag(c"cleanAux", true);
        filter.run()?;
        Ok(Image {
            width: color.width,
            height: color.height,
            pixels: output,
        })
    }
}

/// An OIDN CPU device, released on drop.
struct DeviceGuard<'a> {
    oidn: &'a Oidn,
    device: Device,
}

impl<'a> DeviceGuard<'a> {
    fn new(oidn: &'a Oidn) -> Result<DeviceGuard<'a>> {
        // SAFETY: plain OIDN calls on the device this guard owns.
        let device = unsafe { (oidn.new_device)(DEVICE_TYPE_CPU) };
        if device.is_null() {
            return Err(anyhow!("Open Image Denoise could not create a CPU device"));
        }
        let guard = DeviceGuard { oidn, device };
        unsafe { (oidn.commit_device)(device) };
        guard.check()?;
        Ok(guard)
    }

    /// The device's first error since the last check, as an error.
    fn check(&self) -> Result<()> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: OIDN writes a pointer to a string it owns, valid until the next call.
        let code = unsafe { (self.oidn.get_device_error)(self.device, &mut message) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if message.is_null() {
            String::new()
        } else {
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(anyhow!("Open Image Denoise failed (error {code}): {text}"))
    }

    fn filter(&self) -> Result<FilterGuard<'_, 'a>> {
        // SAFETY: "RT" is a filter type every OIDN 2 build has.
        let filter = unsafe { (self.oidn.new_filter)(self.device, c"RT".as_ptr()) };
        self.check()?;
        if filter.is_null() {
            return Err(anyhow!("Open Image Denoise could not create an RT filter"));
        }
        Ok(FilterGuard {
            device: self,
            filter,
        })
    }
}

impl Drop for DeviceGuard<'_> {
    fn drop(&mut self) {
        // SAFETY: every filter of this device was released first (they borrow the guard).
        unsafe { (self.oidn.release_device)(self.device) };
    }
}

/// An RT filter, released on drop.
struct FilterGuard<'d, 'a> {
    device: &'d DeviceGuard<'a>,
    filter: Filter,
}

impl FilterGuard<'_, '_> {
    /// Binds a tightly packed width × height float3 image that outlives the filter's run.
    fn image(&self, name: &CStr, pixels: *mut c_void, width: usize, height: usize) {
        // SAFETY: `pixels` holds width × height [f32; 3] and stays alive until `run` returns.
        unsafe {
            (self.device.oidn.set_shared_filter_image)(
                self.filter,
                name.as_ptr(),
                pixels,
                FORMAT_FLOAT3,
                width,
                height,
                0,
                12,
                12 * width,
            )
        };
    }

    fn flag(&self, name: &CStr, value: bool) {
        unsafe { (self.device.oidn.set_filter_bool)(self.filter, name.as_ptr(), value) };
    }

    fn run(&self) -> Result<()> {
        unsafe { (self.device.oidn.commit_filter)(self.filter) };
        self.device.check()?;
        unsafe { (self.device.oidn.execute_filter)(self.filter) };
        self.device.check()
    }
}

impl Drop for FilterGuard<'_, '_> {
    fn drop(&mut self) {
        unsafe { (self.device.oidn.release_filter)(self.filter) };
    }
}
