//! The PETSc options database: defaults set by the program, which the command
//! line and PETSC_OPTIONS can override.
use super::{petsc_call, sys, PetscError, Result};
use std::ffi::CString;

fn c_string(s: &str) -> Result<CString> {
    CString::new(s).map_err(|_| PetscError {
        call: "PetscOptions",
        code: -1,
        message: format!("option text contains a NUL byte: {s:?}"),
    })
}

/// Options this program set as defaults (not the user): a later run in the
/// same process may set them differently (e.g. direct solver for a small
/// model, multigrid for a large one), while the user's own options stay.
/// Each is marked with who set it: a scene's `petsc_options` outrank the
/// program's own defaults (but not the command line or PETSC_OPTIONS).
static PROGRAM_SET: std::sync::Mutex<Vec<(String, Source)>> = std::sync::Mutex::new(Vec::new());

/// Who set an option in [`PROGRAM_SET`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    Scene,
    Program,
}

/// Sets `name` (with its leading dash) to `value` unless the user or the
/// scene set it.
pub fn set_default(name: &str, value: &str) -> Result<()> {
    set_as(name, value, Source::Program)
}

fn set_as(name: &str, value: &str, source: Source) -> Result<()> {
    let mut ours = PROGRAM_SET.lock().unwrap_or_else(|e| e.into_inner());
    match ours.iter().find(|(n, _)| n == name).map(|(_, s)| *s) {
        // The scene's value stands against a program default.
        Some(Source::Scene) if source == Source::Program => return Ok(()),
        Some(_) => {}
        None if has(name)? => return Ok(()),
        None => ours.push((name.to_owned(), source)),
    }
    set(name, value)
}

/// Removes every default this program set, before a new run sets its own.
pub fn clear_defaults() -> Result<()> {
    let mut ours = PROGRAM_SET.lock().unwrap_or_else(|e| e.into_inner());
    for (name, _) in ours.drain(..) {
        let n = c_string(&name)?;
        // SAFETY: valid C string; clearing an absent option is not an error.
        unsafe { petsc_call!(PetscOptionsClearValue(std::ptr::null_mut(), n.as_ptr()))? };
    }
    Ok(())
}

/// Sets `name` to `value` unconditionally.
pub fn set(name: &str, value: &str) -> Result<()> {
    let n = c_string(name)?;
    let v = c_string(value)?;
    // SAFETY: both strings are valid NUL-terminated C strings; PETSc copies them.
    unsafe {
        petsc_call!(PetscOptionsSetValue(
            std::ptr::null_mut(),
            n.as_ptr(),
            v.as_ptr()
        ))
    }
}

/// True when the option is in the database and the program did not set it
/// as its default (the command line, PETSC_OPTIONS or a scene's
/// `petsc_options` did).
pub fn user_set(name: &str) -> Result<bool> {
    let ours = PROGRAM_SET.lock().unwrap_or_else(|e| e.into_inner());
    let by_program = ours.iter().any(|(n, s)| n == name && *s == Source::Program);
    drop(ours);
    Ok(!by_program && has(name)?)
}

/// True when the option is present in the database.
pub fn has(name: &str) -> Result<bool> {
    let n = c_string(name)?;
    let mut set = super::sys::PetscBool_PETSC_FALSE;
    // SAFETY: valid C string, `set` is a valid out-pointer.
    unsafe {
        petsc_call!(PetscOptionsHasName(
            std::ptr::null_mut(),
            std::ptr::null(),
            n.as_ptr(),
            &mut set
        ))?;
    }
    Ok(set == super::sys::PetscBool_PETSC_TRUE)
}

/// Inserts a whole option string such as "-ksp_type cg -pc_type gamg".
pub fn insert_string(opts: &str) -> Result<()> {
    let s = c_string(opts)?;
    // SAFETY: valid C string; PETSc parses and copies it.
    unsafe { petsc_call!(PetscOptionsInsertString(std::ptr::null_mut(), s.as_ptr())) }
}

/// Splits an option string "-key value -flag ..." into (key, value) pairs,
/// as PETSc reads it: a word after a key is its value unless it is itself
/// a key (a negative number is a value). Needs no PETSc, so a scene can be
/// checked before PETSc starts.
pub fn parse_pairs(opts: &str) -> std::result::Result<Vec<(&str, &str)>, String> {
    let words: Vec<&str> = opts.split_whitespace().collect();
    let is_key = |w: &str| w.starts_with('-') && w.parse::<f64>().is_err();
    let mut pairs = Vec::new();
    let mut i = 0;
    while i < words.len() {
        let key = words[i];
        if !is_key(key) || key.len() < 2 {
            return Err(format!(
                "expected an option starting with '-', found {key:?} in {opts:?}"
            ));
        }
        match words.get(i + 1).filter(|w| !is_key(w)) {
            Some(v) => {
                pairs.push((key, *v));
                i += 2;
            }
            None => {
                pairs.push((key, ""));
                i += 1;
            }
        }
    }
    Ok(pairs)
}

/// Inserts "-key value" pairs from `opts` (a scene's `petsc_options`) as
/// defaults: keys the user already set (command line, PETSC_OPTIONS) keep
/// the user's value, and the program's defaults set later do not replace
/// these.
pub fn insert_string_defaults(opts: &str) -> Result<()> {
    let pairs = parse_pairs(opts).map_err(|message| PetscError {
        call: "PetscOptions",
        code: -1,
        message,
    })?;
    for (key, value) in pairs {
        set_as(key, value, Source::Scene)?;
    }
    Ok(())
}

/// Options PETSc reads only inside PetscFinalize, after any list of unread
/// options can be taken: they are read, just later. (`-log_view`,
/// `-malloc_dump` and their kind are read at start-up as well.)
const READ_AT_FINALIZE: [&str; 3] = ["-citations", "-options_left", "-options_view"];

/// The options given to this run that nothing has read so far (PETSc keeps
/// the count): from the command line, PETSC_OPTIONS or a scene's
/// `petsc_options`, never the program's own defaults, and not those PETSc
/// reads at finalize. As (name with its leading dash, value; "" for none),
/// in the database's order. Rank-local: PETSc counts the reads of this
/// process.
pub fn unread() -> Result<Vec<(String, String)>> {
    let mut n: super::PetscInt = 0;
    let mut names: *mut *mut std::os::raw::c_char = std::ptr::null_mut();
    let mut values: *mut *mut std::os::raw::c_char = std::ptr::null_mut();
    let text = |p: *mut std::os::raw::c_char| {
        // SAFETY: PETSc's entries are null or NUL-terminated strings of
        // the database, alive until the restore below.
        (!p.is_null()).then(|| {
            unsafe { std::ffi::CStr::from_ptr(p) }
                .to_string_lossy()
                .into_owned()
        })
    };
    let mut left = Vec::new();
    // SAFETY: out-pointers are locals; PETSc fills two arrays of `n`
    // entries, read only before the paired restore frees them.
    unsafe {
        petsc_call!(PetscOptionsLeftGet(
            std::ptr::null_mut(),
            &mut n,
            &mut names,
            &mut values
        ))?;
        if n > 0 && !names.is_null() && !values.is_null() {
            let names = std::slice::from_raw_parts(names, n as usize);
            let values = std::slice::from_raw_parts(values, n as usize);
            for (&k, &v) in names.iter().zip(values) {
                if let Some(k) = text(k) {
                    left.push((format!("-{k}"), text(v).unwrap_or_default()));
                }
            }
        }
        petsc_call!(PetscOptionsLeftRestore(
            std::ptr::null_mut(),
            &mut n,
            &mut names,
            &mut values
        ))?;
    }
    let ours = PROGRAM_SET.lock().unwrap_or_else(|e| e.into_inner());
    let by_program = |k: &str| ours.iter().any(|(n, s)| n == k && *s == Source::Program);
    left.retain(|(k, _)| !by_program(k) && !READ_AT_FINALIZE.contains(&k.as_str()));
    Ok(left)
}

/// Whether something has read the option `name` (with its leading dash)
/// in this process; false when it is not in the database.
pub fn was_read(name: &str) -> Result<bool> {
    let n = c_string(name.strip_prefix('-').unwrap_or(name))?;
    let mut used = sys::PetscBool_PETSC_FALSE;
    // SAFETY: valid C string, `used` is a valid out-pointer.
    unsafe {
        petsc_call!(PetscOptionsUsed(
            std::ptr::null_mut(),
            n.as_ptr(),
            &mut used
        ))?
    };
    Ok(used == sys::PetscBool_PETSC_TRUE)
}

/// The message PETSc gave where its last error started (the innermost
/// call, e.g. "Unable to find requested KSP type nonsense") and its code.
/// PETSc passes it only to the error handler; the code alone names a class
/// ("Unknown type"), not the option or value at fault.
static LAST_ERROR: std::sync::Mutex<Option<(sys::PetscErrorCode, String)>> =
    std::sync::Mutex::new(None);

/// PETSc error handler: keeps the message of the call where an error
/// started and returns the code, printing nothing (as PETSc's
/// `PetscReturnErrorHandler`); the Rust side reports the error with context.
///
/// # Safety
/// Called by PETSc only, with `mess` null or a NUL-terminated string valid
/// for the duration of the call. It never unwinds: a poisoned lock or bad
/// UTF-8 only loses the message.
pub(super) unsafe extern "C" fn keep_error_text(
    _comm: sys::MPI_Comm,
    _line: std::os::raw::c_int,
    _func: *const std::os::raw::c_char,
    _file: *const std::os::raw::c_char,
    code: sys::PetscErrorCode,
    kind: sys::PetscErrorType,
    mess: *const std::os::raw::c_char,
    _ctx: *mut std::os::raw::c_void,
) -> sys::PetscErrorCode {
    if kind == sys::PetscErrorType_PETSC_ERROR_INITIAL && !mess.is_null() {
        // SAFETY: PETSc passes a NUL-terminated message (checked non-null).
        let text = unsafe { std::ffi::CStr::from_ptr(mess) }
            .to_string_lossy()
            .trim()
            .to_owned();
        if let Ok(mut last) = LAST_ERROR.lock() {
            *last = Some((code, text));
        }
    }
    code
}

/// PETSc's own message for the error `code` that a call just returned, if
/// the handler kept one for that code (taken: it is not reused).
pub(super) fn take_error_text(code: sys::PetscErrorCode) -> Option<String> {
    let mut last = LAST_ERROR.lock().ok()?;
    match last.take() {
        Some((c, text)) if c == code && !text.is_empty() => Some(text),
        _ => None,
    }
}

/// Every option in the database as (key, value) pairs: the command line,
/// PETSC_OPTIONS, the scene's `petsc_options` and the program's defaults.
/// Called while an error is being reported, so its own failures are not
/// reported through [`super::check`] (which would call it again): the raw
/// codes are checked here, and a failure gives no options.
fn all_options() -> Option<Vec<(String, String)>> {
    let mut text: *mut std::os::raw::c_char = std::ptr::null_mut();
    // SAFETY: `text` is a valid out-pointer; PETSc allocates the string.
    let code = unsafe { sys::PetscOptionsGetAll(std::ptr::null_mut(), &mut text) };
    if code != 0 {
        let _ = take_error_text(code);
        return None;
    }
    if text.is_null() {
        return None;
    }
    // SAFETY: PetscOptionsGetAll returns a NUL-terminated string.
    let all = unsafe { std::ffi::CStr::from_ptr(text) }
        .to_string_lossy()
        .into_owned();
    let here = c"options.rs";
    // SAFETY: PetscFree(text) as the PetscFree macro expands it: one pointer,
    // passed by address so PETSc can zero it; `text` is not used afterwards.
    let freed = unsafe {
        sys::PetscFreeA(
            1,
            line!() as std::os::raw::c_int,
            here.as_ptr(),
            here.as_ptr(),
            (&mut text as *mut *mut std::os::raw::c_char).cast::<std::os::raw::c_void>(),
        )
    };
    if freed != 0 {
        // A failed free only leaks the string; its message is not about
        // the error being reported.
        let _ = take_error_text(freed);
    }
    Some(
        parse_pairs(&all)
            .unwrap_or_default()
            .into_iter()
            .map(|(k, v)| (k.to_owned(), v.to_owned()))
            .collect(),
    )
}

/// The option a PETSc error message is about: the one whose value the
/// message quotes as a word (PETSc names the rejected value: "Unable to
/// find requested KSP type nonsense", "Input string abc has no numeric
/// value"); the longest such value when several match.
pub(super) fn option_named_by(message: &str) -> Option<(String, String)> {
    let options = all_options()?;
    best_match(message, &options).cloned()
}

fn best_match<'a>(message: &str, options: &'a [(String, String)]) -> Option<&'a (String, String)> {
    let words: Vec<&str> = message
        .split(|c: char| c.is_whitespace() || matches!(c, ',' | ';' | ':' | '"' | '\'' | '(' | ')'))
        .map(|w| w.trim_end_matches('.'))
        .collect();
    options
        .iter()
        .filter(|(_, v)| !v.is_empty() && words.contains(&v.as_str()))
        .max_by_key(|(_, v)| v.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_follow_petsc_reading() {
        assert_eq!(
            parse_pairs("-ksp_type cg -snes_monitor -ksp_rtol 1e-8 -shift -5").unwrap(),
            vec![
                ("-ksp_type", "cg"),
                ("-snes_monitor", ""),
                ("-ksp_rtol", "1e-8"),
                ("-shift", "-5")
            ]
        );
        assert!(parse_pairs("").unwrap().is_empty());
        let e = parse_pairs("ksp_type cg").unwrap_err();
        assert!(e.contains("\"ksp_type\""), "{e}");
        assert!(parse_pairs("-ksp_type cg gmres").is_err());
    }

    #[test]
    fn the_quoted_value_names_the_option() {
        let options: Vec<(String, String)> = [
            ("-pc_type", "lu"),
            ("-ksp_type", "nonsense"),
            ("-ksp_rtol", "abc"),
            ("-snes_monitor", ""),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
        let named = |m: &str| best_match(m, &options).map(|(k, _)| k.as_str());
        assert_eq!(
            named("Unable to find requested KSP type nonsense"),
            Some("-ksp_type")
        );
        assert_eq!(
            named("Input string abc has no numeric value"),
            Some("-ksp_rtol")
        );
        // "lu" inside another word is not a match.
        assert_eq!(named("Could not locate a solver type for lumping"), None);
    }
}
