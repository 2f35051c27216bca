//! The C library interface of LAMMPS and LIGGGHTS (`src/library.h` of each), loaded at run
//! time with `libloading` so that verdem builds and runs where neither is installed. Only the
//! functions both libraries export are used: `lammps_open_no_mpi`, `lammps_command`,
//! `lammps_extract_atom`, `lammps_extract_global` and `lammps_close`; LAMMPS' own
//! `lammps_extract_setting` checks the width of its atom ids.
//!
//! Signatures, as declared in each `library.h`: LAMMPS 2022 (Debian `liblammps0`):
//! `void *lammps_open_no_mpi(int, char **, void **)` returns the handle (a non-null third
//! argument is deprecated and prints a warning); LIGGGHTS 3.8 (Debian `libliggghts3`, on LAMMPS
//! of 2013): `void lammps_open_no_mpi(int, char **, void **)` returns it through the third.
//! Both call `MPI_Init` themselves when MPI is not initialised (a singleton MPI process, no
//! `mpirun` needed) and run on `MPI_COMM_WORLD`.
//!
//! Debian's builds have no C++ exceptions in the library (`lammps_config_has_exceptions()` is
//! 0): an input error ends the whole process (`exit(1)` from `Error::all`, `MPI_Abort` from
//! `Error::one`), and with no screen its message is lost. The driver therefore only sends
//! commands it has checked (a box holding every row, atoms it created), and a hook run at
//! `exit` names the library and the last command it was given.

use std::ffi::{c_char, c_int, c_void, CString};
use std::sync::{Mutex, OnceLock};

use anyhow::{bail, ensure, Context};
use libloading::Library;

/// Which library: the two differ in how `lammps_open_no_mpi` returns its handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flavour {
    /// LAMMPS 2022: the handle is the return value.
    Lammps,
    /// LIGGGHTS 3.8: the handle comes back through the third argument.
    Liggghts,
}

impl Flavour {
    /// The shared object's name (its SONAME, found by the dynamic loader's search).
    pub fn soname(self) -> &'static str {
        match self {
            Flavour::Lammps => "liblammps.so.0",
            Flavour::Liggghts => "libliggghts.so.3",
        }
    }

    /// The Debian package that installs it.
    pub fn package(self) -> &'static str {
        match self {
            Flavour::Lammps => "liblammps0",
            Flavour::Liggghts => "libliggghts3",
        }
    }
}

type OpenReturning = unsafe extern "C" fn(c_int, *mut *mut c_char, *mut *mut c_void) -> *mut c_void;
type OpenThrough = unsafe extern "C" fn(c_int, *mut *mut c_char, *mut *mut c_void);
type Close = unsafe extern "C" fn(*mut c_void);
type Command = unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_char;
type Extract = unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_void;
type Setting = unsafe extern "C" fn(*mut c_void, *const c_char) -> c_int;

enum Open {
    Returning(OpenReturning),
    Through(OpenThrough),
}

/// The loaded library and its functions.
pub struct Api {
    soname: &'static str,
    open: Open,
    close: Close,
    command: Command,
    extract_atom: Extract,
    extract_global: Extract,
    setting: Option<Setting>,
    // declared last: the functions above point into it
    _library: Library,
}

impl Api {
    fn load(flavour: Flavour) -> anyhow::Result<Api> {
        let soname = flavour.soname();
        // SAFETY: loading runs the library's initialisers: those of a C++ library and its MPI,
        // which have no preconditions on the caller.
        let library = unsafe { Library::new(soname) }.with_context(|| {
            format!(
                "cannot load {soname} (install: apt-get install -y {})",
                flavour.package()
            )
        })?;
        // SAFETY: each function is given the type its library.h declares (module doc), and
        // the pointers are kept only beside the library they point into.
        unsafe {
            let open = match flavour {
                Flavour::Lammps => {
                    Open::Returning(function(&library, soname, "lammps_open_no_mpi")?)
                }
                Flavour::Liggghts => {
                    Open::Through(function(&library, soname, "lammps_open_no_mpi")?)
                }
            };
            Ok(Api {
                soname,
                open,
                close: function(&library, soname, "lammps_close")?,
                command: function(&library, soname, "lammps_command")?,
                extract_atom: function(&library, soname, "lammps_extract_atom")?,
                extract_global: function(&library, soname, "lammps_extract_global")?,
                setting: function(&library, soname, "lammps_extract_setting").ok(),
                _library: library,
            })
        }
    }
}

/// The function `name` of `library` (file `soname`), as a pointer of type `T`.
///
/// # Safety
/// `T` must be the function's type.
unsafe fn function<T: Copy>(library: &Library, soname: &str, name: &str) -> anyhow::Result<T> {
    Ok(*library
        .get::<T>(name.as_bytes())
        .with_context(|| format!("{soname}: no function {name}"))?)
}

/// The library of `flavour`, loaded once per process and never unloaded (MPI, once
/// initialised by it, stays so); the error says how to install it.
pub fn api(flavour: Flavour) -> anyhow::Result<&'static Api> {
    static LAMMPS: OnceLock<Result<Api, String>> = OnceLock::new();
    static LIGGGHTS: OnceLock<Result<Api, String>> = OnceLock::new();
    let cell = match flavour {
        Flavour::Lammps => &LAMMPS,
        Flavour::Liggghts => &LIGGGHTS,
    };
    cell.get_or_init(|| Api::load(flavour).map_err(|e| format!("{e:#}")))
        .as_ref()
        .map_err(|e| anyhow::anyhow!("{e}"))
}

/// The library and the command it was last given, for [`report_exit`].
static LAST: Mutex<Option<(&'static str, String)>> = Mutex::new(None);

/// Run at `exit`: if the process ends while a library instance is open (an input error, which
/// Debian's builds turn into `exit(1)`), says which library and command.
extern "C" fn report_exit() {
    if let Ok(last) = LAST.try_lock() {
        if let Some((soname, line)) = last.as_ref() {
            eprintln!(
                "verdem: {soname} ended the process while running `{line}` (an error in its \
                 input; its build has no exceptions, so the message is not shown)"
            );
        }
    }
}

/// One instance of the code (a `LAMMPS` object), closed when dropped. Not `Send`: the
/// libraries keep process-wide state (MPI), so the driver holds a lock while one is open.
pub struct Instance {
    api: &'static Api,
    handle: *mut c_void,
}

impl Instance {
    /// A new instance with no screen output, no log file and no echo.
    pub fn open(api: &'static Api) -> anyhow::Result<Instance> {
        let args: Vec<CString> = ["verdem", "-screen", "none", "-log", "none", "-echo", "none"]
            .iter()
            .map(|a| CString::new(*a).expect("no NUL in the arguments"))
            .collect();
        let mut argv: Vec<*mut c_char> = args.iter().map(|a| a.as_ptr() as *mut c_char).collect();
        let argc = argv.len() as c_int;
        let mut handle: *mut c_void = std::ptr::null_mut();
        // SAFETY: argv holds argc valid C strings that outlive the call (the library copies
        // what it keeps); the handle is written before the call returns.
        unsafe {
            match api.open {
                Open::Returning(f) => handle = f(argc, argv.as_mut_ptr(), std::ptr::null_mut()),
                Open::Through(f) => f(argc, argv.as_mut_ptr(), &mut handle),
            }
        }
        ensure!(!handle.is_null(), "the library returned no instance");
        let instance = Instance { api, handle };
        static HOOK: OnceLock<()> = OnceLock::new();
        HOOK.get_or_init(|| {
            // SAFETY: registers a function with no arguments that only reads a static.
            unsafe { libc::atexit(report_exit) };
        });
        if let Some(setting) = api.setting {
            let name = CString::new("tagint").expect("no NUL");
            // SAFETY: a valid handle and C string.
            let bytes = unsafe { setting(handle, name.as_ptr()) };
            ensure!(
                bytes == 4,
                "atom ids of {bytes} bytes: this driver reads 4-byte ids"
            );
        }
        Ok(instance)
    }

    /// Runs one input line (an error in it ends the process: module doc).
    pub fn command(&mut self, line: &str) -> anyhow::Result<()> {
        let c = CString::new(line).with_context(|| format!("a NUL in the command {line:?}"))?;
        if let Ok(mut last) = LAST.lock() {
            *last = Some((self.api.soname, line.to_string()));
        }
        // SAFETY: a valid handle and C string; the library copies the line.
        unsafe { (self.api.command)(self.handle, c.as_ptr()) };
        Ok(())
    }

    /// Runs every line of `script`.
    pub fn script(&mut self, script: &str) -> anyhow::Result<()> {
        script.lines().try_for_each(|l| self.command(l))
    }

    /// The number of atoms this process owns.
    pub fn nlocal(&self) -> anyhow::Result<usize> {
        let name = CString::new("nlocal").expect("no NUL");
        // SAFETY: "nlocal" is a pointer to the int `atom->nlocal` in both libraries.
        let p = unsafe { (self.api.extract_global)(self.handle, name.as_ptr()) } as *const c_int;
        ensure!(!p.is_null(), "the library gives no nlocal");
        // SAFETY: non-null, pointing to a live int.
        Ok(unsafe { *p } as usize)
    }

    fn atom_pointer(&self, name: &str) -> anyhow::Result<*mut c_void> {
        let c = CString::new(name).expect("no NUL");
        // SAFETY: a valid handle and C string.
        let p = unsafe { (self.api.extract_atom)(self.handle, c.as_ptr()) };
        if p.is_null() {
            bail!("the library has no per-atom {name:?} (atom style without it?)");
        }
        Ok(p)
    }

    /// The ids of the owned atoms, in local order.
    pub fn tags(&self) -> anyhow::Result<Vec<i32>> {
        let n = self.nlocal()?;
        let p = self.atom_pointer("id")? as *const i32;
        // SAFETY: `id` (`atom->tag`) is an array of at least nlocal 4-byte ints (checked in `open`).
        Ok(unsafe { std::slice::from_raw_parts(p, n) }.to_vec())
    }

    /// The 3-vector `name` (x, v, omega, f, torque) of the atom at local index `i`.
    pub fn get(&self, name: &str, i: usize) -> anyhow::Result<[f64; 3]> {
        ensure!(i < self.nlocal()?, "atom index {i} out of range");
        let p = self.atom_pointer(name)? as *const *const f64;
        // SAFETY: a per-atom 3-vector is `double **` with a row of 3 doubles per local atom.
        Ok(unsafe {
            let row = *p.add(i);
            [*row, *row.add(1), *row.add(2)]
        })
    }

    /// Sets the 3-vector `name` of the atom at local index `i`.
    pub fn set(&mut self, name: &str, i: usize, value: [f64; 3]) -> anyhow::Result<()> {
        ensure!(i < self.nlocal()?, "atom index {i} out of range");
        let p = self.atom_pointer(name)? as *const *mut f64;
        // SAFETY: as in `get`; no run is under way, so nothing else reads or writes it.
        unsafe {
            let row = *p.add(i);
            for (k, v) in value.into_iter().enumerate() {
                *row.add(k) = v;
            }
        }
        Ok(())
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: the handle came from `open` and is closed once.
        unsafe { (self.api.close)(self.handle) }
        if let Ok(mut last) = LAST.lock() {
            *last = None;
        }
    }
}
