//! Generates the PETSc bindings (src/petsc/sys.rs includes them) and links PETSc.
//!
//! PETSc comes from Debian's petsc-dev (PETSC_DIR=/usr/lib/petsc, library
//! `petsc_real`); PETSC_DIR and PETSC_LIB override both. MPI types are block-listed
//! here and taken from mpi-sys, so rsmpi communicators pass straight into PETSc.
use std::env;
use std::path::PathBuf;
use std::process::Command;

fn mpi_compile_flags() -> Vec<String> {
    let out = Command::new("mpicc").arg("--showme:compile").output();
    match out {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout)
            .split_whitespace()
            .map(str::to_owned)
            .collect(),
        _ => {
            println!(
                "cargo:warning=mpicc --showme:compile failed; using Debian's OpenMPI include paths"
            );
            vec![
                "-I/usr/lib/x86_64-linux-gnu/openmpi/include".into(),
                "-I/usr/lib/x86_64-linux-gnu/openmpi/include/openmpi".into(),
            ]
        }
    }
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/petsc/wrapper.h");
    println!("cargo:rerun-if-env-changed=PETSC_DIR");
    println!("cargo:rerun-if-env-changed=PETSC_LIB");
    let petsc_dir = env::var("PETSC_DIR").unwrap_or_else(|_| "/usr/lib/petsc".into());
    let petsc_lib = env::var("PETSC_LIB").unwrap_or_else(|_| "petsc_real".into());
    let include = PathBuf::from(&petsc_dir).join("include");
    if !include.join("petsc.h").exists() {
        panic!(
            "petsc.h not found under {} — install Debian's petsc-dev (`make deps`) or set PETSC_DIR",
            include.display()
        );
    }
    println!("cargo:rustc-link-search=native={petsc_dir}/lib");
    println!("cargo:rustc-link-lib={petsc_lib}");
    // The contact Schur path's dense Cholesky calls LAPACK and BLAS itself
    // (src/petsc/dense.rs): the libraries PETSc links, named here because
    // the linker does not take symbols from a library's own dependencies.
    println!("cargo:rustc-link-lib=lapack");
    println!("cargo:rustc-link-lib=blas");
    // The binary must find libpetsc at run time without LD_LIBRARY_PATH.
    println!("cargo:rustc-link-arg=-Wl,-rpath,{petsc_dir}/lib");

    let mut builder = bindgen::Builder::default()
        .header("src/petsc/wrapper.h")
        .clang_arg(format!("-I{}", include.display()))
        .clang_args(mpi_compile_flags())
        .default_macro_constant_type(bindgen::MacroTypeVariation::Signed)
        .default_enum_style(bindgen::EnumVariation::Consts)
        .blocklist_type("MPI_.*")
        .blocklist_type("ompi_.*")
        .blocklist_item("ompi_.*")
        .blocklist_function("MPI_.*")
        .layout_tests(false)
        .derive_default(true)
        .generate_comments(false)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
    for f in [
        "Petsc.*",
        "Vec.*",
        "Mat.*",
        "KSP.*",
        "PC.*",
        "SNES.*",
        "IS.*",
        "ISLocalToGlobalMapping.*",
    ] {
        builder = builder.allowlist_function(f);
    }
    for t in [
        "Petsc.*",
        "_p_.*",
        "Vec",
        "Mat",
        "KSP",
        "PC",
        "SNES",
        "IS",
        "InsertMode",
        "ScatterMode",
        "NormType",
        "MatAssemblyType",
        "MatOption",
        "MatDuplicateOption",
        "MatReuse",
        "KSPConvergedReason",
        "SNESConvergedReason",
        "VecScatter",
        "ISLocalToGlobalMapping",
        "MatNullSpace",
        "PetscBool",
        "PetscInt",
        "PetscScalar",
        "PetscReal",
        "PetscErrorCode",
        "PetscCopyMode",
        "PetscLogStage",
        "PetscLogEvent",
    ] {
        builder = builder.allowlist_type(t);
    }
    for v in [
        "PETSC_.*",
        "KSP_.*",
        "SNES_.*",
        "MAT_.*",
        "INSERT_VALUES",
        "ADD_VALUES",
        "NORM_.*",
        "SCATTER_.*",
        "PETSC_COMM_WORLD",
        "PetscOptions.*",
    ] {
        builder = builder.allowlist_var(v);
    }
    let bindings = builder
        .generate()
        .expect("bindgen failed on petsc.h (is libclang-dev installed?)");
    let out = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR")).join("petsc_bindings.rs");
    bindings
        .write_to_file(&out)
        .expect("could not write the PETSc bindings");
}
