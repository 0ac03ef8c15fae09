//! A model without its mesh as flat `u64` words, for one broadcast: rank 0
//! reads the mesh and resolves the scene against it, and the other ranks get
//! only what the resolution found (materials, Dirichlet node lists, loads,
//! contact pairs, settings). Nothing here is of the mesh's size: the largest
//! arrays are the Dirichlet sets' node lists and values.
//!
//! Every struct is taken apart with an exhaustive pattern, so a field added
//! to the model fails to compile here until it travels too.
use super::{
    DirichletSpec, DynamicsSpec, FacetLoad, Formulation, FrictionSpec, MasterSpec, Model, Newmark,
    PairSpec, Reuse, RigidSurface, SlaveQuadrature, SolverSettings,
};
use crate::amplitude::Amplitude;
use crate::error::{Error, Result};
use crate::fem::{CellType, Integration, Material};
use crate::hertz::{HertzCheck, HertzKind};
use crate::mesh::Mesh;

/// Words in, in the order [`Reader`] takes them out.
#[derive(Debug, Default)]
pub struct Writer {
    pub words: Vec<u64>,
}

impl Writer {
    pub fn usize(&mut self, v: usize) {
        self.words.push(v as u64);
    }

    pub fn f64(&mut self, v: f64) {
        self.words.push(v.to_bits());
    }

    pub fn bool(&mut self, v: bool) {
        self.words.push(u64::from(v));
    }

    pub fn vec3(&mut self, v: [f64; 3]) {
        v.into_iter().for_each(|x| self.f64(x));
    }

    /// Length, then the bytes packed eight to a word.
    pub fn bytes(&mut self, b: &[u8]) {
        self.usize(b.len());
        for chunk in b.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.words.push(u64::from_le_bytes(w));
        }
    }

    pub fn str(&mut self, s: &str) {
        self.bytes(s.as_bytes());
    }

    pub fn opt_f64(&mut self, v: Option<f64>) {
        self.bool(v.is_some());
        self.f64(v.unwrap_or(0.0));
    }
}

/// Takes out what a [`Writer`] put in; a short or malformed message is an
/// internal error (both ends run the same program).
pub struct Reader<'a> {
    words: &'a [u64],
    at: usize,
}

impl<'a> Reader<'a> {
    pub fn new(words: &'a [u64]) -> Self {
        Reader { words, at: 0 }
    }

    fn word(&mut self) -> Result<u64> {
        let w = self.words.get(self.at).copied().ok_or_else(|| {
            Error::Internal(format!(
                "the broadcast model ends after {} words",
                self.words.len()
            ))
        })?;
        self.at += 1;
        Ok(w)
    }

    pub fn usize(&mut self) -> Result<usize> {
        self.word().map(|w| w as usize)
    }

    /// A count of items of at least `per` words each that the rest of the
    /// message can hold, so a corrupt count cannot ask for a huge allocation.
    fn len(&mut self, per: usize) -> Result<usize> {
        self.checked_len(|n| n.saturating_mul(per))
    }

    fn checked_len(&mut self, words: impl Fn(usize) -> usize) -> Result<usize> {
        let n = self.usize()?;
        let left = self.words.len() - self.at;
        if words(n) > left {
            return Err(Error::Internal(format!(
                "the broadcast model has a length {n} beyond its {left} remaining words"
            )));
        }
        Ok(n)
    }

    pub fn f64(&mut self) -> Result<f64> {
        self.word().map(f64::from_bits)
    }

    pub fn bool(&mut self) -> Result<bool> {
        Ok(self.word()? != 0)
    }

    pub fn vec3(&mut self) -> Result<[f64; 3]> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }

    pub fn bytes(&mut self) -> Result<Vec<u8>> {
        let n = self.checked_len(|n| n.div_ceil(8))?;
        let mut b = Vec::with_capacity(n);
        for _ in 0..n.div_ceil(8) {
            b.extend_from_slice(&self.word()?.to_le_bytes());
        }
        b.truncate(n);
        Ok(b)
    }

    pub fn str(&mut self) -> Result<String> {
        String::from_utf8(self.bytes()?)
            .map_err(|e| Error::Internal(format!("the broadcast model has a bad string: {e}")))
    }

    pub fn opt_f64(&mut self) -> Result<Option<f64>> {
        let some = self.bool()?;
        let v = self.f64()?;
        Ok(some.then_some(v))
    }

    /// `n` items read by `item`, `n` first.
    fn list<T>(
        &mut self,
        per: usize,
        mut item: impl FnMut(&mut Self) -> Result<T>,
    ) -> Result<Vec<T>> {
        let n = self.len(per)?;
        (0..n).map(|_| item(self)).collect()
    }

    /// Whether every word was read.
    pub fn finished(&self) -> bool {
        self.at == self.words.len()
    }
}

/// The model without its mesh (only the cell type travels). A spatial body
/// force `b(X)` is a closure, which no message carries: a scene never has
/// one, so a model with one is refused.
pub fn encode(model: &Model, w: &mut Writer) -> Result<()> {
    let Model {
        name,
        mesh,
        materials,
        integration,
        dirichlet,
        facet_loads,
        body_force,
        body_force_fn,
        contact,
        hertz,
        steps,
        solver,
        dynamics,
    } = model;
    if body_force_fn.is_some() {
        return Err(Error::Internal(
            "a model with a body force function b(X) cannot be broadcast".into(),
        ));
    }
    w.str(name);
    // The position in `CellType::ALL` (hex8 0, tet4 1, ...).
    let code = CellType::ALL.iter().position(|&c| c == mesh.cell_type);
    w.usize(code.unwrap_or(0));
    w.usize(materials.len());
    for m in materials {
        let (tag, youngs, poisson) = match *m {
            Material::LinearElastic { youngs, poisson } => (0, youngs, poisson),
            Material::NeoHookean { youngs, poisson } => (1, youngs, poisson),
        };
        w.usize(tag);
        w.f64(youngs);
        w.f64(poisson);
    }
    w.usize(integration.len());
    for i in integration {
        w.usize(match i {
            Integration::Full => 0,
            Integration::Reduced => 1,
        });
    }
    w.usize(dirichlet.len());
    for d in dirichlet {
        put_dirichlet(w, d);
    }
    w.usize(facet_loads.len());
    for (set, load, amplitude) in facet_loads {
        w.str(set);
        match *load {
            FacetLoad::Pressure(p) => {
                w.usize(0);
                w.vec3([p, 0.0, 0.0]);
            }
            FacetLoad::Traction(t) => {
                w.usize(1);
                w.vec3(t);
            }
        }
        put_amplitude(w, amplitude);
    }
    w.usize(body_force.len());
    body_force.iter().for_each(|&b| w.vec3(b));
    w.usize(contact.len());
    for p in contact {
        put_pair(w, p);
    }
    w.bool(hertz.is_some());
    if let Some(h) = hertz {
        let HertzCheck {
            kind,
            pair,
            radius,
            effective_modulus,
        } = h;
        match *kind {
            HertzKind::Line { thickness } => {
                w.usize(0);
                w.f64(thickness);
            }
            HertzKind::Point => {
                w.usize(1);
                w.f64(0.0);
            }
        }
        w.str(pair);
        w.f64(*radius);
        w.f64(*effective_modulus);
    }
    w.usize(*steps);
    put_solver(w, solver);
    w.bool(dynamics.is_some());
    if let Some(d) = dynamics {
        let DynamicsSpec {
            time_step,
            newmark: Newmark { beta, gamma },
            density,
            initial_velocity,
        } = d;
        w.f64(*time_step);
        w.f64(*beta);
        w.f64(*gamma);
        w.usize(density.len());
        density.iter().for_each(|&r| w.f64(r));
        w.usize(initial_velocity.len());
        initial_velocity.iter().for_each(|&v| w.vec3(v));
    }
    Ok(())
}

/// What [`encode`] wrote, with an empty mesh of the sent cell type.
pub fn decode(r: &mut Reader) -> Result<Model> {
    let bad = |what: &str, v: usize| Error::Internal(format!("the broadcast model has {what} {v}"));
    let name = r.str()?;
    let code = r.usize()?;
    let cell_type = *CellType::ALL
        .get(code)
        .ok_or_else(|| bad("cell type", code))?;
    let materials = r.list(3, |r| {
        let (tag, youngs, poisson) = (r.usize()?, r.f64()?, r.f64()?);
        match tag {
            0 => Ok(Material::LinearElastic { youngs, poisson }),
            1 => Ok(Material::NeoHookean { youngs, poisson }),
            t => Err(bad("material", t)),
        }
    })?;
    let integration = r.list(1, |r| match r.usize()? {
        0 => Ok(Integration::Full),
        1 => Ok(Integration::Reduced),
        t => Err(bad("integration", t)),
    })?;
    let dirichlet = r.list(4, take_dirichlet)?;
    let facet_loads = r.list(6, |r| {
        let set = r.str()?;
        let (tag, v) = (r.usize()?, r.vec3()?);
        let load = match tag {
            0 => FacetLoad::Pressure(v[0]),
            1 => FacetLoad::Traction(v),
            t => return Err(bad("facet load", t)),
        };
        Ok((set, load, take_amplitude(r)?))
    })?;
    let body_force = r.list(3, Reader::vec3)?;
    // At least 18 words a pair (empty strings, a surface master).
    let contact = r.list(18, take_pair)?;
    let hertz = if r.bool()? {
        let (tag, thickness) = (r.usize()?, r.f64()?);
        let kind = match tag {
            0 => HertzKind::Line { thickness },
            1 => HertzKind::Point,
            t => return Err(bad("Hertz kind", t)),
        };
        Some(HertzCheck {
            kind,
            pair: r.str()?,
            radius: r.f64()?,
            effective_modulus: r.f64()?,
        })
    } else {
        None
    };
    let steps = r.usize()?;
    let solver = take_solver(r)?;
    let dynamics = if r.bool()? {
        Some(DynamicsSpec {
            time_step: r.f64()?,
            newmark: Newmark {
                beta: r.f64()?,
                gamma: r.f64()?,
            },
            density: r.list(1, Reader::f64)?,
            initial_velocity: r.list(3, Reader::vec3)?,
        })
    } else {
        None
    };
    Ok(Model {
        name,
        mesh: Mesh::empty(cell_type),
        materials,
        integration,
        dirichlet,
        facet_loads,
        body_force,
        body_force_fn: None,
        contact,
        hertz,
        steps,
        solver,
        dynamics,
    })
}

fn put_amplitude(w: &mut Writer, a: &Amplitude) {
    w.usize(a.points().len());
    for &(f, v) in a.points() {
        w.f64(f);
        w.f64(v);
    }
}

fn take_amplitude(r: &mut Reader) -> Result<Amplitude> {
    let table = r.list(2, |r| Ok([r.f64()?, r.f64()?]))?;
    Amplitude::from_table(&table)
        .map_err(|e| Error::Internal(format!("the broadcast model has an amplitude that {e}")))
}

fn put_dirichlet(w: &mut Writer, d: &DirichletSpec) {
    let DirichletSpec {
        set,
        nodes,
        components,
        values,
        amplitude,
    } = d;
    w.str(set);
    w.usize(nodes.len());
    nodes.iter().for_each(|&n| w.usize(n));
    w.usize(components.len());
    components.iter().for_each(|&c| w.usize(c));
    w.usize(values.len());
    values.iter().for_each(|&v| w.vec3(v));
    put_amplitude(w, amplitude);
}

fn take_dirichlet(r: &mut Reader) -> Result<DirichletSpec> {
    Ok(DirichletSpec {
        set: r.str()?,
        nodes: r.list(1, Reader::usize)?,
        components: r.list(1, Reader::usize)?,
        values: r.list(3, Reader::vec3)?,
        amplitude: take_amplitude(r)?,
    })
}

fn put_pair(w: &mut Writer, p: &PairSpec) {
    let PairSpec {
        name,
        slave,
        master,
        formulation,
        quadrature,
        motion,
        motion_amplitude,
        penalty,
        penetration_tol,
        multiplier_tol,
        max_uzawa,
        search_distance,
        friction,
    } = p;
    w.str(name);
    w.str(slave);
    match master {
        MasterSpec::Surface { set } => {
            w.usize(0);
            w.str(set);
        }
        MasterSpec::Rigid(s) => {
            w.usize(1);
            put_rigid(w, s);
        }
    }
    w.usize(match formulation {
        Formulation::Links => 0,
        Formulation::Mortar => 1,
    });
    w.usize(match quadrature {
        SlaveQuadrature::Gauss => 0,
        SlaveQuadrature::Nodal => 1,
        SlaveQuadrature::Centroid => 2,
    });
    w.vec3(*motion);
    put_amplitude(w, motion_amplitude);
    w.opt_f64(*penalty);
    w.f64(*penetration_tol);
    w.f64(*multiplier_tol);
    w.usize(*max_uzawa);
    w.opt_f64(*search_distance);
    w.bool(friction.is_some());
    if let Some(FrictionSpec { mu, penalty }) = friction {
        w.f64(*mu);
        w.opt_f64(*penalty);
    }
}

fn take_pair(r: &mut Reader) -> Result<PairSpec> {
    let bad = |what: &str, v: usize| Error::Internal(format!("the broadcast model has {what} {v}"));
    let name = r.str()?;
    let slave = r.str()?;
    let master = match r.usize()? {
        0 => MasterSpec::Surface { set: r.str()? },
        1 => MasterSpec::Rigid(take_rigid(r)?),
        t => return Err(bad("master kind", t)),
    };
    let formulation = match r.usize()? {
        0 => Formulation::Links,
        1 => Formulation::Mortar,
        t => return Err(bad("formulation", t)),
    };
    let quadrature = match r.usize()? {
        0 => SlaveQuadrature::Gauss,
        1 => SlaveQuadrature::Nodal,
        2 => SlaveQuadrature::Centroid,
        t => return Err(bad("slave quadrature", t)),
    };
    Ok(PairSpec {
        name,
        slave,
        master,
        formulation,
        quadrature,
        motion: r.vec3()?,
        motion_amplitude: take_amplitude(r)?,
        penalty: r.opt_f64()?,
        penetration_tol: r.f64()?,
        multiplier_tol: r.f64()?,
        max_uzawa: r.usize()?,
        search_distance: r.opt_f64()?,
        friction: if r.bool()? {
            Some(FrictionSpec {
                mu: r.f64()?,
                penalty: r.opt_f64()?,
            })
        } else {
            None
        },
    })
}

/// Kind, then three vectors and a radius (unused ones zero).
fn put_rigid(w: &mut Writer, s: &RigidSurface) {
    let (kind, a, b, radius) = match *s {
        RigidSurface::Plane { point, normal } => (0, point, normal, 0.0),
        RigidSurface::Sphere { centre, radius } => (1, centre, [0.0; 3], radius),
        RigidSurface::Cylinder {
            point,
            axis,
            radius,
        } => (2, point, axis, radius),
    };
    w.usize(kind);
    w.vec3(a);
    w.vec3(b);
    w.f64(radius);
}

fn take_rigid(r: &mut Reader) -> Result<RigidSurface> {
    let (kind, a, b, radius) = (r.usize()?, r.vec3()?, r.vec3()?, r.f64()?);
    match kind {
        0 => Ok(RigidSurface::Plane {
            point: a,
            normal: b,
        }),
        1 => Ok(RigidSurface::Sphere { centre: a, radius }),
        2 => Ok(RigidSurface::Cylinder {
            point: a,
            axis: b,
            radius,
        }),
        t => Err(Error::Internal(format!(
            "the broadcast model has rigid surface kind {t}"
        ))),
    }
}

fn put_solver(w: &mut Writer, s: &SolverSettings) {
    let SolverSettings {
        max_newton,
        rtol,
        atol,
        direct_max_dofs,
        max_cutbacks,
        petsc_options,
        reuse:
            Reuse {
                linear_stiffness,
                pattern,
                preconditioner,
                active_set,
            },
        extrapolate,
        uzawa_forcing,
        first_contact_softening,
        first_contact_main_tangent,
        contact_schur,
        condensed_newton,
        uzawa_acceleration,
    } = s;
    w.usize(*max_newton);
    w.f64(*rtol);
    w.opt_f64(*atol);
    w.usize(*direct_max_dofs);
    w.usize(*max_cutbacks);
    w.str(petsc_options);
    for b in [linear_stiffness, pattern, preconditioner, active_set] {
        w.bool(*b);
    }
    w.bool(*extrapolate);
    w.f64(*uzawa_forcing);
    w.f64(*first_contact_softening);
    w.bool(*first_contact_main_tangent);
    w.bool(*contact_schur);
    w.bool(*condensed_newton);
    w.bool(uzawa_acceleration.is_some());
    w.usize(uzawa_acceleration.unwrap_or(0));
}

fn take_solver(r: &mut Reader) -> Result<SolverSettings> {
    Ok(SolverSettings {
        max_newton: r.usize()?,
        rtol: r.f64()?,
        atol: r.opt_f64()?,
        direct_max_dofs: r.usize()?,
        max_cutbacks: r.usize()?,
        petsc_options: r.str()?,
        reuse: Reuse {
            linear_stiffness: r.bool()?,
            pattern: r.bool()?,
            preconditioner: r.bool()?,
            active_set: r.bool()?,
        },
        extrapolate: r.bool()?,
        uzawa_forcing: r.f64()?,
        first_contact_softening: r.f64()?,
        first_contact_main_tangent: r.bool()?,
        contact_schur: r.bool()?,
        condensed_newton: r.bool()?,
        uzawa_acceleration: {
            let set = r.bool()?;
            let depth = r.usize()?;
            set.then_some(depth)
        },
    })
}

#[cfg(test)]
mod tests;
