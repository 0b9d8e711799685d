//! Multibody model: named nodes and elements, built programmatically or from a deck.
use super::beam::{Beam, BeamLoad, SectionLoad, NPTS_M};
use super::joint::{Joint, JointKind};
use super::kin::NodeKin;
use super::rigid::{PointLoad, RigidBody};
use super::rotation::*;
use super::section::SectionTable;
use nalgebra::{UnitQuaternion, Vector3};
use std::collections::HashMap;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ModelError {
    #[error("unknown node `{0}`")]
    UnknownNode(String),
    #[error("duplicate name `{0}`")]
    Duplicate(String),
    #[error("{0}")]
    Invalid(String),
}

/// Error returned by a user element; aborts the current step.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("element `{element}`: {msg}")]
pub struct ElementError {
    pub element: String,
    pub msg: String,
}

/// Output of a [`StepElement`] evaluation: forces it applies on its two nodes (global) and
/// their derivatives with respect to the current node positions `x_f`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ElementOutput {
    /// `force[k]`: force applied by the element on node k [N].
    pub force: [[f64; 3]; 2],
    /// `jac[k][l][i][j] = d force[k][i] / d x_f[l][j]` [N/m].
    pub jac: [[[[f64; 3]; 3]; 2]; 2],
}

/// User element with internal state acting on the translational dofs of two nodes (e.g. a
/// hydraulic damper, paper Eqs. 9-16). Called at every Newton iterate with the positions at the
/// last converged time `t_i` and at the current iterate (`t_i + dt`); `commit` is called once
/// when a step converges, never for rejected iterates. Static analyses call with `dt = 0`.
pub trait StepElement: Send {
    fn name(&self) -> &str;
    fn nodes(&self) -> [usize; 2];
    fn evaluate(
        &mut self,
        t_i: f64,
        dt: f64,
        x_i: [[f64; 3]; 2],
        x_f: [[f64; 3]; 2],
        out: &mut ElementOutput,
    ) -> Result<(), ElementError>;
    fn commit(&mut self);
    /// Size of the forces the element's force is made of at the committed state [N] (the
    /// round-off of its force is relative to it; Newton's convergence floor). Default: 0, the
    /// element adds nothing to the model's force scale.
    fn force_scale(&self) -> f64 {
        0.0
    }
    /// Whether the following `evaluate` calls need `jac` (false: only `force` is read, so an
    /// element may skip the work of its derivative). Default: ignored.
    fn want_jacobian(&mut self, _yes: bool) {}
    /// Named scalar outputs (units in the name), written by sensors.
    fn sensors(&self) -> Vec<(String, f64)> {
        vec![]
    }
    /// The committed state as numbers (saved states of a simulation: periodic solutions,
    /// warm starts). Default: stateless.
    fn state_values(&self) -> Vec<f64> {
        vec![]
    }
    /// Restores a state of [`StepElement::state_values`]; drops any trial state.
    fn set_state_values(&mut self, v: &[f64]) -> Result<(), String> {
        if v.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "element {} has no state, got {} values",
                self.name(),
                v.len()
            ))
        }
    }
}

/// Where an externally supplied distributed load is evaluated.
#[derive(Clone, Copy, Debug)]
pub struct LoadPoint {
    pub t: f64,
    /// Beam element index and reference arc length along its beam [m].
    pub element: usize,
    pub s_m: f64,
    pub x: [f64; 3],
    /// Section rotation (columns: section axes 1, 2, 3 in global).
    pub r: [[f64; 3]; 3],
    pub v: [f64; 3],
    pub w: [f64; 3],
}

/// Externally supplied distributed load on beam elements (aerodynamics, ...). Evaluated once per
/// residual evaluation at each inertia quadrature point; returns force and moment per unit
/// length, global or follower (section frame; the follower load stiffness enters the tangent).
pub trait DistributedLoad: Send {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad;
}

/// Node of the model: reference and current configuration.
#[derive(Clone, Debug)]
pub struct Node {
    pub name: String,
    pub x0: [f64; 3],
    pub q0: UnitQuaternion<f64>,
}

/// Built-in elements.
// Beams are the common case in a model; storing them inline keeps the element loop contiguous.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Element {
    Beam(Beam),
    Rigid(RigidBody),
    Joint(Joint),
    Load(PointLoad),
}

impl Element {
    pub fn name(&self) -> &str {
        match self {
            Element::Beam(b) => &b.name,
            Element::Rigid(b) => &b.name,
            Element::Joint(b) => &b.name,
            Element::Load(b) => &b.name,
        }
    }
    /// Node indices (joint to ground: only node B).
    pub fn node_list(&self) -> Vec<usize> {
        match self {
            Element::Beam(b) => b.nodes.to_vec(),
            Element::Rigid(b) => vec![b.node],
            Element::Load(b) => vec![b.node],
            Element::Joint(j) => match j.node_a {
                Some(a) => vec![a, j.node_b],
                None => vec![j.node_b],
            },
        }
    }
    pub fn n_lambda(&self) -> usize {
        match self {
            Element::Joint(j) => j.n_lambda(),
            _ => 0,
        }
    }
}

/// What a sensor records.
#[derive(Clone, Debug, PartialEq)]
pub enum SensorKind {
    /// Node position, rotation vector, velocity and angular velocity (global).
    Node(usize),
    /// Joint reaction force/moment on node B (global) and relative angle.
    Joint(usize),
    /// Beam section forces (section frame) at the stiffness point nearest to `s_m` of a beam.
    Section { elements: Vec<usize>, s_m: f64 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    pub name: String,
    pub kind: SensorKind,
}

/// A multibody model.
pub struct Model {
    pub nodes: Vec<Node>,
    pub elements: Vec<Element>,
    pub step_elements: Vec<Box<dyn StepElement>>,
    pub dist_loads: Vec<(Vec<usize>, Box<dyn DistributedLoad>)>,
    pub sensors: Vec<Sensor>,
    pub gravity: [f64; 3],
    node_names: HashMap<String, usize>,
    elem_names: HashMap<String, usize>,
    /// Beam name -> element indices in order along the beam.
    pub beams: HashMap<String, Vec<usize>>,
    /// Nodes whose unknowns couple otherwise separate parts (a hub between blades): the solver
    /// factors the parts as blocks of a bordered LU with these as the border. Empty: one LU.
    pub border_nodes: Vec<usize>,
}

impl Default for Model {
    fn default() -> Self {
        Self::new()
    }
}

/// Build the reference frame of a beam whose axis is `e1`, with `e2` as close as possible to
/// `hint`.
pub fn frame_from_axis(e1: [f64; 3], hint: [f64; 3]) -> [[f64; 3]; 3] {
    let n = dot(e1, e1).sqrt();
    let e1 = fmul(1.0 / n, e1);
    let mut h = hint;
    if dot(cross(e1, h), cross(e1, h)) < 1e-12 {
        h = if e1[2].abs() < 0.9 {
            [0.0, 0.0, 1.0]
        } else {
            [1.0, 0.0, 0.0]
        };
    }
    let e3 = cross(e1, h);
    let e3 = fmul(1.0 / dot(e3, e3).sqrt(), e3);
    let e2 = cross(e3, e1);
    [
        [e1[0], e2[0], e3[0]],
        [e1[1], e2[1], e3[1]],
        [e1[2], e2[2], e3[2]],
    ]
}

fn quat_from_arr(r: &[[f64; 3]; 3]) -> UnitQuaternion<f64> {
    let lv = log_map(r);
    UnitQuaternion::from_scaled_axis(Vector3::from(lv))
}

impl Model {
    pub fn new() -> Self {
        Model {
            nodes: vec![],
            elements: vec![],
            step_elements: vec![],
            dist_loads: vec![],
            sensors: vec![],
            gravity: [0.0; 3],
            node_names: HashMap::new(),
            elem_names: HashMap::new(),
            beams: HashMap::new(),
            border_nodes: vec![],
        }
    }

    pub fn add_node(
        &mut self,
        name: &str,
        x0: [f64; 3],
        r0: [[f64; 3]; 3],
    ) -> Result<usize, ModelError> {
        if self.node_names.contains_key(name) || name == "ground" {
            return Err(ModelError::Duplicate(name.into()));
        }
        self.nodes.push(Node {
            name: name.into(),
            x0,
            q0: quat_from_arr(&r0),
        });
        self.node_names.insert(name.into(), self.nodes.len() - 1);
        Ok(self.nodes.len() - 1)
    }

    pub fn node_id(&self, name: &str) -> Result<usize, ModelError> {
        self.node_names
            .get(name)
            .copied()
            .ok_or_else(|| ModelError::UnknownNode(name.into()))
    }

    pub fn element_id(&self, name: &str) -> Option<usize> {
        self.elem_names.get(name).copied()
    }

    pub fn node_r0(&self, i: usize) -> [[f64; 3]; 3] {
        quat_to_arr(&self.nodes[i].q0)
    }

    pub fn add_element(&mut self, e: Element) -> Result<usize, ModelError> {
        let name = e.name().to_string();
        if self.elem_names.contains_key(&name) {
            return Err(ModelError::Duplicate(name));
        }
        for n in e.node_list() {
            if n >= self.nodes.len() {
                return Err(ModelError::Invalid(format!(
                    "element `{name}` refers to node index {n}, model has {}",
                    self.nodes.len()
                )));
            }
        }
        self.elements.push(e);
        self.elem_names.insert(name, self.elements.len() - 1);
        Ok(self.elements.len() - 1)
    }

    /// Add a beam along a parametrised reference line `curve(s) -> (x, R)` for s in [0, length],
    /// with `n_elem` cubic elements. Nodes are named `{name}.n{k}` (k = 0..3 n_elem); if
    /// `first_node` is given it is used as node 0 (connects to an existing node).
    #[allow(clippy::too_many_arguments)]
    pub fn add_beam(
        &mut self,
        name: &str,
        n_elem: usize,
        length: f64,
        curve: &dyn Fn(f64) -> ([f64; 3], [[f64; 3]; 3]),
        sections: &SectionTable,
        damping_mu_s: f64,
        first_node: Option<usize>,
    ) -> Result<Vec<usize>, ModelError> {
        if n_elem == 0 || length <= 0.0 {
            return Err(ModelError::Invalid(format!(
                "beam `{name}`: needs at least one element and positive length"
            )));
        }
        let nn = 3 * n_elem + 1;
        let mut ids = Vec::with_capacity(nn);
        for k in 0..nn {
            if k == 0 {
                if let Some(f) = first_node {
                    ids.push(f);
                    continue;
                }
            }
            let s = length * k as f64 / (nn - 1) as f64;
            let (x, r) = curve(s);
            ids.push(self.add_node(&format!("{name}.n{k}"), x, r)?);
        }
        let mut elems = vec![];
        for e in 0..n_elem {
            let nodes = [ids[3 * e], ids[3 * e + 1], ids[3 * e + 2], ids[3 * e + 3]];
            let x0 = nodes.map(|i| self.nodes[i].x0);
            let r0 = nodes.map(|i| self.node_r0(i));
            let s0 = length * e as f64 / n_elem as f64;
            let b = Beam::new(
                &format!("{name}.e{e}"),
                nodes,
                &x0,
                &r0,
                sections,
                s0,
                damping_mu_s,
            );
            elems.push(self.add_element(Element::Beam(b))?);
        }
        self.beams.insert(name.into(), elems);
        Ok(ids)
    }

    /// Straight beam from `a` to `b` with section axis 2 close to `e2_hint`.
    #[allow(clippy::too_many_arguments)]
    pub fn add_straight_beam(
        &mut self,
        name: &str,
        n_elem: usize,
        a: [f64; 3],
        b: [f64; 3],
        e2_hint: [f64; 3],
        sections: &SectionTable,
        damping_mu_s: f64,
        first_node: Option<usize>,
    ) -> Result<Vec<usize>, ModelError> {
        let d = sub(b, a);
        let len = dot(d, d).sqrt();
        let r = frame_from_axis(d, e2_hint);
        let f = move |s: f64| (add(a, fmul(s / len, d)), r);
        self.add_beam(name, n_elem, len, &f, sections, damping_mu_s, first_node)
    }

    /// Add a constant distributed load on all elements of a beam.
    pub fn add_beam_load(&mut self, beam: &str, load: BeamLoad) -> Result<(), ModelError> {
        let ids = self
            .beams
            .get(beam)
            .cloned()
            .ok_or_else(|| ModelError::Invalid(format!("unknown beam `{beam}`")))?;
        for i in ids {
            if let Element::Beam(b) = &mut self.elements[i] {
                b.loads.push(load.clone());
            }
        }
        Ok(())
    }

    /// Attach an external distributed load provider to a beam.
    pub fn add_distributed_load(
        &mut self,
        beam: &str,
        load: Box<dyn DistributedLoad>,
    ) -> Result<(), ModelError> {
        let ids = self
            .beams
            .get(beam)
            .cloned()
            .ok_or_else(|| ModelError::Invalid(format!("unknown beam `{beam}`")))?;
        self.dist_loads.push((ids, load));
        Ok(())
    }

    pub fn add_step_element(&mut self, e: Box<dyn StepElement>) -> Result<usize, ModelError> {
        for n in e.nodes() {
            if n >= self.nodes.len() {
                return Err(ModelError::Invalid(format!(
                    "element `{}` refers to node index {n}",
                    e.name()
                )));
            }
        }
        self.step_elements.push(e);
        Ok(self.step_elements.len() - 1)
    }

    /// Joint with frame `q` (columns = axes, global; z = revolute axis) at point `p`.
    pub fn add_joint(
        &mut self,
        name: &str,
        kind: JointKind,
        node_a: Option<usize>,
        node_b: usize,
        p: [f64; 3],
        q: [[f64; 3]; 3],
    ) -> Result<usize, ModelError> {
        if node_a == Some(node_b) {
            return Err(ModelError::Invalid(format!(
                "joint `{name}` connects node `{}` to itself",
                self.nodes[node_b].name
            )));
        }
        let a = node_a.map(|i| (i, self.nodes[i].x0, self.node_r0(i)));
        let b = (node_b, self.nodes[node_b].x0, self.node_r0(node_b));
        self.add_element(Element::Joint(Joint::new(name, kind, a, b, p, q)))
    }

    /// Clamp a node to the ground at its reference position.
    pub fn clamp(&mut self, name: &str, node: usize) -> Result<usize, ModelError> {
        let p = self.nodes[node].x0;
        self.add_joint(name, JointKind::Clamp, None, node, p, ident())
    }

    pub fn add_sensor(&mut self, name: &str, kind: SensorKind) {
        self.sensors.push(Sensor {
            name: name.into(),
            kind,
        });
    }

    pub fn n_lambda(&self) -> usize {
        self.elements.iter().map(|e| e.n_lambda()).sum()
    }

    /// Reference kinematics of all nodes (at rest).
    pub fn reference_state(&self) -> Vec<NodeKin<f64>> {
        self.nodes
            .iter()
            .map(|n| NodeKin {
                x: n.x0,
                r: quat_to_arr(&n.q0),
                ..NodeKin::ground()
            })
            .collect()
    }

    /// Evaluate external distributed-load providers and cache their values in the beams.
    pub fn update_distributed_loads(&mut self, t: f64, kin: &[NodeKin<f64>]) {
        let elements = &mut self.elements;
        for (ids, prov) in self.dist_loads.iter_mut() {
            for &ei in ids.iter() {
                if let Element::Beam(b) = &mut elements[ei] {
                    let k = b.nodes.map(|i| kin[i]);
                    let pts = b.load_points_cached(&k);
                    let mut ext = [SectionLoad::default(); NPTS_M];
                    for q in 0..NPTS_M {
                        let (x, r, v, w) = pts[q];
                        ext[q] = prov.eval(&LoadPoint {
                            t,
                            element: ei,
                            s_m: b.gm[q].s_m,
                            x,
                            r,
                            v,
                            w,
                        });
                    }
                    b.ext = ext;
                }
            }
        }
    }
}
