//! Newton, load-stepping and reuse settings of a run (`[solver]`; the
//! solver itself is in `solve`).

/// The default `[solver] uzawa_forcing`: a non-final Newton solve stops
/// at 1e-3 of its starting residual.
pub const DEFAULT_FORCING: f64 = 1e-3;

/// The default `[solver] uzawa_acceleration` on the Krylov path (Anderson
/// depth; the direct path's default is 0, off).
pub const DEFAULT_ACCELERATION: usize = 1;
/// The largest depth `[solver] uzawa_acceleration` accepts.
pub const MAX_ACCELERATION: usize = 3;

/// Newton and load-stepping settings.
#[derive(Debug, Clone)]
pub struct SolverSettings {
    pub max_newton: usize,
    pub rtol: f64,
    /// Absolute residual tolerance; None: rtol × the residual at the start of
    /// each load step (the step's own force scale), so small loads and large
    /// ones converge alike, and Uzawa's follow-up solves stay as tight.
    pub atol: Option<f64>,
    /// Models with at most this many DOFs default to a direct solver
    /// (MUMPS; PETSc's own for the smallest on one rank), robust for stiff
    /// contact penalties; larger ones to Krylov + algebraic multigrid.
    pub direct_max_dofs: usize,
    pub max_cutbacks: usize,
    /// PETSc options (defaults that the command line and PETSC_OPTIONS override).
    pub petsc_options: String,
    /// What is computed once and reused (all on by default; switches exist
    /// to measure each saving).
    pub reuse: Reuse,
    /// Start each load step from the last two converged steps extrapolated
    /// to the new load, instead of from the last one. Off by default: it
    /// saves Newton iterations on smooth load paths (block-slide 60 → 51)
    /// but costs them where the contact set changes between steps
    /// (hertz-cylinder 23 → 24, and a cutback with the l2 line search).
    pub extrapolate: bool,
    /// Newton inside a non-final Uzawa iteration stops once its residual
    /// fell by this factor (see `tolerance`); 0: every solve to the final
    /// tolerance.
    pub uzawa_forcing: f64,
    /// A step that starts with no contact anywhere (every λN = 0) runs its
    /// first Uzawa iteration with every frictionless pair's penalty divided
    /// by this factor (1: off); see `solve::uzawa`.
    pub first_contact_softening: f64,
    /// The first Uzawa iteration of a step that starts with no contact
    /// assembles the frictionless links' tangent without its terms in the
    /// pressure times the derivatives of the normal (see `solve::uzawa`).
    pub first_contact_main_tangent: bool,
    /// On the direct path with linear bodies on one rank, factor the bulk
    /// stiffness once with a Schur complement on the contact DOFs and solve
    /// each contact Jacobian through it (see `linsolve`).
    pub contact_schur: bool,
    /// On the contact Schur path, Newton on the condensed contact system
    /// (the same iterates; the interior formed once per step, see
    /// `linsolve::schur::newton` on one rank, `linsolve::low_rank::newton` on
    /// several).
    pub condensed_newton: bool,
    /// Depth of the Anderson acceleration of the frictionless pairs'
    /// Uzawa multiplier updates (0: off; see `solve::anderson`); None: the
    /// default of the linear solver's path (`solve::tolerance`).
    pub uzawa_acceleration: Option<usize>,
}

/// Work a run reuses instead of redoing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reuse {
    /// Linear-elastic bulk stiffness assembled once (residual = K u − f).
    pub linear_stiffness: bool,
    /// Jacobian sparsity pattern kept while the contact couplings are unchanged.
    pub pattern: bool,
    /// Preconditioner (LU factors) of an Uzawa iteration's first solve kept
    /// for the following ones.
    pub preconditioner: bool,
    /// Preconditioner rebuilt only when the contact active set changed
    /// (within Newton too), see `lagging`; off: rebuilt every Newton
    /// iteration of a step's first Uzawa iteration.
    pub active_set: bool,
}

impl Default for Reuse {
    fn default() -> Self {
        Reuse {
            linear_stiffness: true,
            pattern: true,
            preconditioner: true,
            active_set: true,
        }
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_newton: 30,
            rtol: 1e-9,
            atol: None,
            direct_max_dofs: 20_000,
            max_cutbacks: 8,
            petsc_options: String::new(),
            reuse: Reuse::default(),
            extrapolate: false,
            uzawa_forcing: DEFAULT_FORCING,
            first_contact_softening: 1.0,
            first_contact_main_tangent: true,
            contact_schur: true,
            condensed_newton: true,
            uzawa_acceleration: None,
        }
    }
}
