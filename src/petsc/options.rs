//! The PETSc options database: defaults set by the program, which the command
//! line and PETSC_OPTIONS can override.
use super::{petsc_call, PetscError, Result};
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
static PROGRAM_SET: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// Sets `name` (with its leading dash) to `value` unless the user set it.
pub fn set_default(name: &str, value: &str) -> Result<()> {
    let mut ours = PROGRAM_SET.lock().unwrap_or_else(|e| e.into_inner());
    let is_ours = ours.iter().any(|n| n == name);
    if !is_ours && has(name)? {
        return Ok(());
    }
    if !is_ours {
        ours.push(name.to_owned());
    }
    set(name, value)
}

/// Removes every default this program set, before a new run sets its own.
pub fn clear_defaults() -> Result<()> {
    let mut ours = PROGRAM_SET.lock().unwrap_or_else(|e| e.into_inner());
    for name in ours.drain(..) {
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

/// Inserts "-key value" pairs from `opts` as defaults: keys the user already
/// set (command line, PETSC_OPTIONS) keep the user's value.
pub fn insert_string_defaults(opts: &str) -> Result<()> {
    let pairs = parse_pairs(opts).map_err(|message| PetscError {
        call: "PetscOptions",
        code: -1,
        message,
    })?;
    for (key, value) in pairs {
        set_default(key, value)?;
    }
    Ok(())
}
