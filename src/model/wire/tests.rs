use super::*;
use crate::fem::CellType;

/// A model with every optional part present and values that a lossy
/// encoding would change (non-round floats, empty strings, rigid masters).
fn full_model() -> Model {
    let mut d = DirichletSpec::uniform(
        "b.bottom",
        vec![3, 1, 4, 1 << 40],
        vec![0, 2],
        [0.1, 0.0, -1e-300],
    );
    d.amplitude = Amplitude::from_table(&[[0.0, 0.0], [0.3, 1.0 / 3.0], [1.0, 0.7]]).unwrap();
    let mut rigid = PairSpec::new(
        "ball",
        "b.top",
        MasterSpec::Rigid(RigidSurface::Cylinder {
            point: [0.5, f64::MIN_POSITIVE, 2.0],
            axis: [0.0, 1.0, 0.0],
            radius: 0.25,
        }),
    );
    rigid.motion = [0.0, 0.0, -0.1];
    rigid.penalty = Some(1.5e7);
    rigid.friction = Some(FrictionSpec {
        mu: 0.3,
        penalty: None,
    });
    rigid.quadrature = SlaveQuadrature::Centroid;
    let mut surface = PairSpec::new(
        "",
        "",
        MasterSpec::Surface {
            set: "a.top".into(),
        },
    );
    surface.formulation = Formulation::Mortar;
    surface.search_distance = Some(0.125);
    let solver = SolverSettings {
        atol: Some(1e-12),
        petsc_options: "-ksp_type cg -pc_type gamg ü".into(),
        extrapolate: true,
        ..SolverSettings::default()
    };
    Model {
        name: "a model named ✓".into(),
        mesh: Mesh::empty(CellType::Tet4),
        materials: vec![
            Material::LinearElastic {
                youngs: 1000.0,
                poisson: 0.3,
            },
            Material::NeoHookean {
                youngs: 2.0e5,
                poisson: 0.49,
            },
        ],
        integration: vec![Integration::Full, Integration::Reduced],
        dirichlet: vec![d],
        facet_loads: vec![
            ("p".into(), FacetLoad::Pressure(-2.5), Amplitude::ramp()),
            (
                "t".into(),
                FacetLoad::Traction([1.0, 2.0, 3.0]),
                Amplitude::ramp(),
            ),
        ],
        body_force: vec![[0.0, 0.0, -9.81], [0.0; 3]],
        body_force_fn: None,
        contact: vec![rigid, surface],
        hertz: Some(HertzCheck {
            kind: HertzKind::Line { thickness: 0.2 },
            pair: "ball".into(),
            radius: 10.0,
            effective_modulus: 549.45,
        }),
        steps: 7,
        solver,
        dynamics: Some(DynamicsSpec {
            time_step: 1e-3,
            newmark: Newmark::with_dissipation(0.6),
            density: vec![7.8e3, 1.0],
            initial_velocity: vec![[0.0, 0.0, -1.0], [0.0; 3]],
        }),
    }
}

fn words(m: &Model) -> Vec<u64> {
    let mut w = Writer::default();
    encode(m, &mut w).unwrap();
    w.words
}

#[test]
fn a_model_comes_back_as_it_was_sent() {
    let sent = full_model();
    let w = words(&sent);
    let mut r = Reader::new(&w);
    let got = decode(&mut r).unwrap();
    assert!(r.finished());
    // Sending what arrived gives the same words: every field made the trip.
    assert_eq!(words(&got), w);
    assert_eq!(got.name, sent.name);
    assert_eq!(got.mesh.cell_type, CellType::Tet4);
    assert_eq!(got.mesh.num_nodes(), 0);
    assert_eq!(
        format!("{:?}", got.materials),
        format!("{:?}", sent.materials)
    );
    assert_eq!(
        format!("{:?}", got.dirichlet),
        format!("{:?}", sent.dirichlet)
    );
    assert_eq!(
        format!("{:?}", got.facet_loads),
        format!("{:?}", sent.facet_loads)
    );
    assert_eq!(format!("{:?}", got.contact), format!("{:?}", sent.contact));
    assert_eq!(got.hertz, sent.hertz);
    assert_eq!(format!("{:?}", got.solver), format!("{:?}", sent.solver));
    assert_eq!(
        format!("{:?}", got.dynamics),
        format!("{:?}", sent.dynamics)
    );
    assert_eq!(got.steps, 7);
}

#[test]
fn a_cut_message_is_an_error_not_a_panic() {
    let w = words(&full_model());
    for n in [0, 1, 5, w.len() / 2, w.len() - 1] {
        assert!(decode(&mut Reader::new(&w[..n])).is_err(), "{n} words");
    }
}

#[test]
fn a_body_force_function_is_refused() {
    let mut m = full_model();
    m.body_force_fn = Some(Box::new(|x| x));
    assert!(encode(&m, &mut Writer::default()).is_err());
}
