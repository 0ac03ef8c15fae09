//! Why a SNES or KSP solve stopped, as enums built from PETSc's own
//! constants (bindgen), so a number can never be read with the wrong
//! meaning (the table of one PETSc version against the codes of another).
use super::sys;
use std::fmt;

/// SNESConvergedReason (PETSc 3.18).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SnesReason {
    Iterating,
    FnormAbs,
    FnormRelative,
    SnormRelative,
    Iterations,
    FunctionDomain,
    FunctionCount,
    LinearSolve,
    FnormNan,
    MaxIterations,
    LineSearch,
    Inner,
    LocalMin,
    Dtol,
    JacobianDomain,
    TrustRegionDelta,
    /// A code this build's PETSc headers do not define.
    Other(i32),
}

impl SnesReason {
    pub fn from_raw(code: sys::SNESConvergedReason) -> Self {
        use SnesReason::*;
        match code {
            sys::SNESConvergedReason_SNES_CONVERGED_ITERATING => Iterating,
            sys::SNESConvergedReason_SNES_CONVERGED_FNORM_ABS => FnormAbs,
            sys::SNESConvergedReason_SNES_CONVERGED_FNORM_RELATIVE => FnormRelative,
            sys::SNESConvergedReason_SNES_CONVERGED_SNORM_RELATIVE => SnormRelative,
            sys::SNESConvergedReason_SNES_CONVERGED_ITS => Iterations,
            sys::SNESConvergedReason_SNES_DIVERGED_FUNCTION_DOMAIN => FunctionDomain,
            sys::SNESConvergedReason_SNES_DIVERGED_FUNCTION_COUNT => FunctionCount,
            sys::SNESConvergedReason_SNES_DIVERGED_LINEAR_SOLVE => LinearSolve,
            sys::SNESConvergedReason_SNES_DIVERGED_FNORM_NAN => FnormNan,
            sys::SNESConvergedReason_SNES_DIVERGED_MAX_IT => MaxIterations,
            sys::SNESConvergedReason_SNES_DIVERGED_LINE_SEARCH => LineSearch,
            sys::SNESConvergedReason_SNES_DIVERGED_INNER => Inner,
            sys::SNESConvergedReason_SNES_DIVERGED_LOCAL_MIN => LocalMin,
            sys::SNESConvergedReason_SNES_DIVERGED_DTOL => Dtol,
            sys::SNESConvergedReason_SNES_DIVERGED_JACOBIAN_DOMAIN => JacobianDomain,
            sys::SNESConvergedReason_SNES_DIVERGED_TR_DELTA => TrustRegionDelta,
            other => Other(other),
        }
    }

    pub fn converged(self) -> bool {
        matches!(
            self,
            SnesReason::FnormAbs
                | SnesReason::FnormRelative
                | SnesReason::SnormRelative
                | SnesReason::Iterations
        )
    }
}

impl fmt::Display for SnesReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use SnesReason::*;
        let text = match self {
            Iterating => "stopped while still iterating",
            FnormAbs => "converged: |R| < atol",
            FnormRelative => "converged: |R| < rtol |R0|",
            SnormRelative => "converged: |dx| < stol |x|",
            Iterations => "converged: iteration limit (ksponly)",
            FunctionDomain => "diverged: the residual is outside its domain",
            FunctionCount => "diverged: residual evaluation limit reached",
            LinearSolve => "diverged: the linear solve failed",
            FnormNan => "diverged: NaN or Inf in the residual norm",
            MaxIterations => "diverged: maximum Newton iterations reached",
            LineSearch => "diverged: the line search failed",
            Inner => "diverged: inner solve failed",
            LocalMin => "diverged: stuck in a local minimum of |R|",
            Dtol => "diverged: |R| exceeded the divergence tolerance",
            JacobianDomain => "diverged: the Jacobian is outside its domain",
            TrustRegionDelta => "diverged: trust region too small",
            Other(code) => return write!(f, "SNESConvergedReason {code} (not defined by the PETSc headers this program was built with)"),
        };
        f.write_str(text)
    }
}

/// KSPConvergedReason (PETSc 3.18) of the last linear solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KspReason {
    Iterating,
    RtolNormal,
    AtolNormal,
    Rtol,
    Atol,
    Iterations,
    CgNegativeCurvature,
    CgConstrained,
    StepLength,
    HappyBreakdown,
    Null,
    MaxIterations,
    Dtol,
    Breakdown,
    BreakdownBicg,
    Nonsymmetric,
    IndefinitePc,
    NanOrInf,
    IndefiniteMat,
    PcFailed,
    Other(i32),
}

impl KspReason {
    pub fn from_raw(code: sys::KSPConvergedReason) -> Self {
        use KspReason::*;
        match code {
            sys::KSPConvergedReason_KSP_CONVERGED_ITERATING => Iterating,
            sys::KSPConvergedReason_KSP_CONVERGED_RTOL_NORMAL => RtolNormal,
            sys::KSPConvergedReason_KSP_CONVERGED_ATOL_NORMAL => AtolNormal,
            sys::KSPConvergedReason_KSP_CONVERGED_RTOL => Rtol,
            sys::KSPConvergedReason_KSP_CONVERGED_ATOL => Atol,
            sys::KSPConvergedReason_KSP_CONVERGED_ITS => Iterations,
            sys::KSPConvergedReason_KSP_CONVERGED_CG_NEG_CURVE => CgNegativeCurvature,
            sys::KSPConvergedReason_KSP_CONVERGED_CG_CONSTRAINED => CgConstrained,
            sys::KSPConvergedReason_KSP_CONVERGED_STEP_LENGTH => StepLength,
            sys::KSPConvergedReason_KSP_CONVERGED_HAPPY_BREAKDOWN => HappyBreakdown,
            sys::KSPConvergedReason_KSP_DIVERGED_NULL => Null,
            sys::KSPConvergedReason_KSP_DIVERGED_ITS => MaxIterations,
            sys::KSPConvergedReason_KSP_DIVERGED_DTOL => Dtol,
            sys::KSPConvergedReason_KSP_DIVERGED_BREAKDOWN => Breakdown,
            sys::KSPConvergedReason_KSP_DIVERGED_BREAKDOWN_BICG => BreakdownBicg,
            sys::KSPConvergedReason_KSP_DIVERGED_NONSYMMETRIC => Nonsymmetric,
            sys::KSPConvergedReason_KSP_DIVERGED_INDEFINITE_PC => IndefinitePc,
            sys::KSPConvergedReason_KSP_DIVERGED_NANORINF => NanOrInf,
            sys::KSPConvergedReason_KSP_DIVERGED_INDEFINITE_MAT => IndefiniteMat,
            sys::KSPConvergedReason_KSP_DIVERGED_PC_FAILED => PcFailed,
            other => Other(other),
        }
    }
}

impl fmt::Display for KspReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use KspReason::*;
        let text = match self {
            Iterating => "KSP_CONVERGED_ITERATING (no linear solve yet)",
            RtolNormal => "KSP_CONVERGED_RTOL_NORMAL",
            AtolNormal => "KSP_CONVERGED_ATOL_NORMAL",
            Rtol => "KSP_CONVERGED_RTOL",
            Atol => "KSP_CONVERGED_ATOL",
            Iterations => "KSP_CONVERGED_ITS",
            CgNegativeCurvature => "KSP_CONVERGED_CG_NEG_CURVE",
            CgConstrained => "KSP_CONVERGED_CG_CONSTRAINED",
            StepLength => "KSP_CONVERGED_STEP_LENGTH",
            HappyBreakdown => "KSP_CONVERGED_HAPPY_BREAKDOWN",
            Null => "KSP_DIVERGED_NULL",
            MaxIterations => "KSP_DIVERGED_ITS (iteration limit)",
            Dtol => "KSP_DIVERGED_DTOL (residual grew)",
            Breakdown => "KSP_DIVERGED_BREAKDOWN",
            BreakdownBicg => "KSP_DIVERGED_BREAKDOWN_BICG",
            Nonsymmetric => "KSP_DIVERGED_NONSYMMETRIC (the method needs a symmetric matrix)",
            IndefinitePc => "KSP_DIVERGED_INDEFINITE_PC",
            NanOrInf => "KSP_DIVERGED_NANORINF (NaN or Inf in the linear solve)",
            IndefiniteMat => "KSP_DIVERGED_INDEFINITE_MAT",
            PcFailed => "KSP_DIVERGED_PC_FAILED (the preconditioner, e.g. the factorisation, failed)",
            Other(code) => return write!(f, "KSPConvergedReason {code} (not defined by the PETSc headers this program was built with)"),
        };
        f.write_str(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_solve_failure_is_not_read_as_a_nan_residual() {
        let r = SnesReason::from_raw(sys::SNESConvergedReason_SNES_DIVERGED_LINEAR_SOLVE);
        assert_eq!(r, SnesReason::LinearSolve);
        assert!(r.to_string().contains("linear solve"), "{r}");
        assert!(!r.converged());
    }

    #[test]
    fn every_defined_code_has_its_own_name() {
        // 1 is not a SNES reason in PETSc 3.18.
        for code in (-11..=5).filter(|c| *c != 1) {
            let r = SnesReason::from_raw(code);
            assert!(!matches!(r, SnesReason::Other(_)), "SNES code {code}");
            assert!(!r.to_string().contains("unknown"));
        }
        for code in -11..=9 {
            if code == -1 {
                continue; // not a KSP reason in PETSc 3.18
            }
            assert!(
                !matches!(KspReason::from_raw(code), KspReason::Other(_)),
                "KSP code {code}"
            );
        }
        assert!(SnesReason::from_raw(-99).to_string().contains("-99"));
    }
}
