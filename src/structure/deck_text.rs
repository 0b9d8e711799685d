//! A typed model deck as TOML text (docs/model_deck.md): the one writer of a [`Deck`], and a
//! builder of generated decks that records how they are laid out (comments, the order of their
//! items), so that what `rotorsim expand` prints is the typed deck a run builds.
use super::deck::{
    ArcDeck, BeamDeck, Deck, DistDeck, DynamicDeck, HydraulicDeck, JointDeck, LoadDeck, ModesDeck,
    NodeDeck, RigidDeck, SensorDeck, StaticDeck,
};
use super::section::SectionProps;

/// The item tables (`[[node]]`, ...) of a deck.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Node,
    Beam,
    RigidBody,
    Joint,
    Load,
    DistributedLoad,
    Hydraulic,
    Sensor,
}

impl Kind {
    /// In the order a deck without a layout is printed.
    const ALL: [Kind; 8] = [
        Kind::Node,
        Kind::Beam,
        Kind::RigidBody,
        Kind::Joint,
        Kind::Load,
        Kind::DistributedLoad,
        Kind::Hydraulic,
        Kind::Sensor,
    ];

    fn table(self) -> &'static str {
        match self {
            Kind::Node => "node",
            Kind::Beam => "beam",
            Kind::RigidBody => "rigid_body",
            Kind::Joint => "joint",
            Kind::Load => "load",
            Kind::DistributedLoad => "distributed_load",
            Kind::Hydraulic => "hydraulic",
            Kind::Sensor => "sensor",
        }
    }

    fn count(self, d: &Deck) -> usize {
        match self {
            Kind::Node => d.nodes.len(),
            Kind::Beam => d.beams.len(),
            Kind::RigidBody => d.rigid_bodies.len(),
            Kind::Joint => d.joints.len(),
            Kind::Load => d.loads.len(),
            Kind::DistributedLoad => d.distributed_loads.len(),
            Kind::Hydraulic => d.hydraulics.len(),
            Kind::Sensor => d.sensors.len(),
        }
    }
}

/// One entry of a printed deck: an item (its table and index) or a comment on its own.
#[derive(Clone, Debug, Default)]
pub struct Entry {
    /// The item printed; None: the comment alone, followed by a blank line.
    pub item: Option<(Kind, usize)>,
    /// Comment lines printed before it (without the `# `).
    pub comment: Vec<String>,
    /// Spaces before the item's table header.
    pub indent: usize,
    /// The item's keys in the order printed, when not the writer's (keys not listed follow).
    pub keys: Option<&'static [&'static str]>,
}

/// How a deck is printed. Not part of what it builds: decks equal in everything else compare
/// equal whatever their layout (a deck read from text has none).
#[derive(Clone, Debug, Default)]
pub struct Layout {
    /// Comment lines before the title (without the `# `).
    pub header: Vec<String>,
    /// The entries in the order printed; items not listed follow, table by table.
    pub entries: Vec<Entry>,
}

impl PartialEq for Layout {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Builds a deck item by item, recording the order and comments of its text.
#[derive(Default)]
pub struct DeckBuilder {
    deck: Deck,
}

impl DeckBuilder {
    pub fn new(header: Vec<String>, title: &str) -> Self {
        let mut deck = Deck {
            title: Some(title.to_string()),
            ..Default::default()
        };
        deck.layout.header = header;
        DeckBuilder { deck }
    }

    /// Comment lines on their own.
    pub fn note(&mut self, lines: Vec<String>) {
        self.deck.layout.entries.push(Entry {
            comment: lines,
            ..Default::default()
        });
    }

    fn place(&mut self, kind: Kind, index: usize) -> &mut Entry {
        let entries = &mut self.deck.layout.entries;
        let at = entries.len();
        entries.push(Entry {
            item: Some((kind, index)),
            ..Default::default()
        });
        &mut entries[at]
    }

    pub fn node(&mut self, n: NodeDeck) -> &mut Entry {
        self.deck.nodes.push(n);
        self.place(Kind::Node, self.deck.nodes.len() - 1)
    }
    pub fn beam(&mut self, b: BeamDeck) -> &mut Entry {
        self.deck.beams.push(b);
        self.place(Kind::Beam, self.deck.beams.len() - 1)
    }
    pub fn rigid_body(&mut self, r: RigidDeck) -> &mut Entry {
        self.deck.rigid_bodies.push(r);
        self.place(Kind::RigidBody, self.deck.rigid_bodies.len() - 1)
    }
    pub fn joint(&mut self, j: JointDeck) -> &mut Entry {
        self.deck.joints.push(j);
        self.place(Kind::Joint, self.deck.joints.len() - 1)
    }
    pub fn load(&mut self, l: LoadDeck) -> &mut Entry {
        self.deck.loads.push(l);
        self.place(Kind::Load, self.deck.loads.len() - 1)
    }
    pub fn hydraulic(&mut self, h: HydraulicDeck) -> &mut Entry {
        self.deck.hydraulics.push(h);
        self.place(Kind::Hydraulic, self.deck.hydraulics.len() - 1)
    }
    pub fn sensor(&mut self, s: SensorDeck) -> &mut Entry {
        self.deck.sensors.push(s);
        self.place(Kind::Sensor, self.deck.sensors.len() - 1)
    }

    /// The deck so far (for its analysis tables).
    pub fn deck_mut(&mut self) -> &mut Deck {
        &mut self.deck
    }

    pub fn finish(self) -> Deck {
        self.deck
    }
}

/// A value as TOML reads it back exactly (Rust's shortest round-trip form).
fn f(v: f64) -> String {
    format!("{v:?}")
}

fn list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| f(*x)).collect();
    format!("[{}]", items.join(", "))
}

fn pairs(t: &[[f64; 2]]) -> String {
    let items: Vec<String> = t.iter().map(|p| list(p)).collect();
    format!("[{}]", items.join(", "))
}

fn matrix(m: &[[f64; 3]; 3]) -> String {
    let rows: Vec<String> = m.iter().map(|r| list(r)).collect();
    format!("[{}]", rows.join(", "))
}

/// A TOML basic string.
fn q(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

fn inline(keys: &[(&str, String)]) -> String {
    let items: Vec<String> = keys.iter().map(|(k, v)| format!("{k} = {v}")).collect();
    format!("{{ {} }}", items.join(", "))
}

/// A section as an inline table: the offsets (and `s_m`) only where non-zero.
fn section(p: &SectionProps) -> String {
    let mut keys = vec![];
    if p.s_m != 0.0 {
        keys.push(("s_m", f(p.s_m)));
    }
    for (k, v) in [
        ("EA_N", p.ea),
        ("GA2_N", p.ga2),
        ("GA3_N", p.ga3),
        ("GJ_Nm2", p.gj),
        ("EI2_Nm2", p.ei2),
        ("EI3_Nm2", p.ei3),
        ("m_kg_per_m", p.m),
        ("I1_kgm", p.i1),
        ("I2_kgm", p.i2),
        ("I3_kgm", p.i3),
    ] {
        keys.push((k, f(v)));
    }
    for (k, v) in [
        ("cm2_m", p.cm2),
        ("cm3_m", p.cm3),
        ("sc2_m", p.sc2),
        ("sc3_m", p.sc3),
        ("ca2_m", p.ca2),
        ("ca3_m", p.ca3),
    ] {
        if v != 0.0 {
            keys.push((k, f(v)));
        }
    }
    inline(&keys)
}

fn arc(a: &ArcDeck) -> String {
    inline(&[
        ("center_m", list(&a.center_m)),
        ("radius_m", f(a.radius_m)),
        ("start_deg", f(a.start_deg)),
        ("end_deg", f(a.end_deg)),
        ("normal", list(&a.normal)),
        ("zero_direction", list(&a.zero_direction)),
    ])
}

/// Key-value lines of one table, in the writer's order.
type Lines = Vec<(&'static str, String)>;

fn push<T>(l: &mut Lines, key: &'static str, v: &Option<T>, show: impl Fn(&T) -> String) {
    if let Some(v) = v {
        l.push((key, show(v)));
    }
}

fn node_lines(n: &NodeDeck) -> Lines {
    let mut l = vec![("name", q(&n.name)), ("position_m", list(&n.position_m))];
    if n.rotation_vector_rad != [0.0; 3] {
        l.push(("rotation_vector_rad", list(&n.rotation_vector_rad)));
    }
    l
}

fn beam_lines(b: &BeamDeck) -> Lines {
    let mut l = vec![("name", q(&b.name)), ("elements", b.elements.to_string())];
    push(&mut l, "start_node", &b.start_node, |s| q(s));
    push(&mut l, "e2_direction", &b.e2_direction, |v| list(v));
    push(&mut l, "start_m", &b.start_m, |v| list(v));
    push(&mut l, "end_m", &b.end_m, |v| list(v));
    push(&mut l, "arc", &b.arc, arc);
    push(&mut l, "sections_csv", &b.sections_csv, |s| q(s));
    push(&mut l, "section", &b.section, section);
    push(&mut l, "sections", &b.sections, |v| {
        let items: Vec<String> = v.iter().map(section).collect();
        format!("[{}]", items.join(", "))
    });
    push(&mut l, "damping_mu_s", &b.damping_mu_s, |v| f(*v));
    push(&mut l, "twist_deg", &b.twist_deg, |t| pairs(t));
    l
}

fn rigid_lines(r: &RigidDeck) -> Lines {
    let mut l = vec![
        ("name", q(&r.name)),
        ("node", q(&r.node)),
        ("mass_kg", f(r.mass_kg)),
    ];
    push(&mut l, "cm_offset_m", &r.cm_offset_m, |v| list(v));
    l.push(("inertia_kgm2", matrix(&r.inertia_kgm2)));
    l
}

fn joint_lines(j: &JointDeck) -> Lines {
    let mut l = vec![("name", q(&j.name)), ("type", q(&j.kind))];
    push(&mut l, "node_a", &j.node_a, |s| q(s));
    l.push(("node_b", q(&j.node_b)));
    push(&mut l, "position_m", &j.position_m, |v| list(v));
    push(&mut l, "axis", &j.axis, |v| list(v));
    push(&mut l, "x_direction", &j.x_direction, |v| list(v));
    push(&mut l, "stiffness_Nm_per_rad", &j.stiffness, |v| f(*v));
    push(&mut l, "damping_Nms_per_rad", &j.damping, |v| f(*v));
    push(&mut l, "elastomer", &j.elastomer, |e| {
        inline(&[
            ("loss_factor", f(e.loss_factor)),
            ("band_rad_s", list(&e.band_rad_s)),
            ("reference_rad_s", f(e.reference_rad_s)),
        ])
    });
    push(&mut l, "omega_rad_s", &j.omega_rad_s, |v| f(*v));
    push(&mut l, "angle_table", &j.angle_table, |t| pairs(t));
    push(&mut l, "displacement_m", &j.displacement_m, |v| list(v));
    push(&mut l, "displacement_table", &j.displacement_table, |t| {
        pairs(t)
    });
    push(&mut l, "locked", &j.locked, |v| {
        let items: Vec<String> = v.iter().map(|s| q(s)).collect();
        format!("[{}]", items.join(", "))
    });
    push(&mut l, "stiffness_N_per_m", &j.stiffness_t, |v| list(v));
    push(&mut l, "damping_Ns_per_m", &j.damping_t, |v| list(v));
    push(&mut l, "rot_stiffness_Nm_per_rad", &j.stiffness_r, |v| {
        list(v)
    });
    push(&mut l, "rot_damping_Nms_per_rad", &j.damping_r, |v| list(v));
    l
}

fn load_lines(l: &LoadDeck) -> Lines {
    let mut out = vec![
        ("name", q(&l.name)),
        ("node", q(&l.node)),
        ("force_N", list(&l.force)),
        ("moment_Nm", list(&l.moment)),
    ];
    if l.follower {
        out.push(("follower", "true".into()));
    }
    push(&mut out, "time_table", &l.time_table, |t| pairs(t));
    out
}

fn dist_lines(l: &DistDeck) -> Lines {
    let mut out = vec![
        ("beam", q(&l.beam)),
        ("force_N_per_m", list(&l.force)),
        ("moment_Nm_per_m", list(&l.moment)),
    ];
    if l.follower {
        out.push(("follower", "true".into()));
    }
    push(&mut out, "time_table", &l.time_table, |t| pairs(t));
    out
}

fn hydraulic_lines(h: &HydraulicDeck) -> Lines {
    let mut l = vec![("name", q(&h.name)), ("node_a", q(&h.node_a))];
    push(&mut l, "position_m", &h.position_m, |v| list(v));
    l.push(("node_b", q(&h.node_b)));
    l.push(("deck", q(&h.deck)));
    push(&mut l, "model", &h.model, |s| q(s));
    push(&mut l, "scheme", &h.scheme, |s| q(s));
    push(&mut l, "substeps", &h.substeps, |n| n.to_string());
    push(&mut l, "orifice_area_table", &h.orifice_area_table, |t| {
        pairs(t)
    });
    push(&mut l, "reference_length_m", &h.reference_length_m, |v| {
        f(*v)
    });
    push(&mut l, "applied_force", &h.applied_force, |s| q(s));
    l
}

fn sensor_lines(s: &SensorDeck) -> Lines {
    let mut l = vec![("name", q(&s.name))];
    push(&mut l, "node", &s.node, |n| q(n));
    push(&mut l, "joint", &s.joint, |n| q(n));
    push(&mut l, "beam", &s.beam, |n| q(n));
    push(&mut l, "s_m", &s.s_m, |v| f(*v));
    l
}

fn item_lines(d: &Deck, kind: Kind, i: usize) -> Option<Lines> {
    Some(match kind {
        Kind::Node => node_lines(d.nodes.get(i)?),
        Kind::Beam => beam_lines(d.beams.get(i)?),
        Kind::RigidBody => rigid_lines(d.rigid_bodies.get(i)?),
        Kind::Joint => joint_lines(d.joints.get(i)?),
        Kind::Load => load_lines(d.loads.get(i)?),
        Kind::DistributedLoad => dist_lines(d.distributed_loads.get(i)?),
        Kind::Hydraulic => hydraulic_lines(d.hydraulics.get(i)?),
        Kind::Sensor => sensor_lines(d.sensors.get(i)?),
    })
}

fn static_lines(s: &StaticDeck) -> Lines {
    let dflt = StaticDeck::default();
    let mut l = vec![("load_steps", s.load_steps.to_string())];
    if s.max_iterations != dflt.max_iterations {
        l.push(("max_iterations", s.max_iterations.to_string()));
    }
    push(&mut l, "omega_rad_s", &s.omega_rad_s, |v| list(v));
    l
}

fn dynamic_lines(d: &DynamicDeck) -> Lines {
    let dflt = DynamicDeck::default();
    let mut l = vec![];
    push(&mut l, "time_step_s", &d.time_step_s, |v| f(*v));
    push(&mut l, "end_time_s", &d.end_time_s, |v| f(*v));
    if d.rho_inf != dflt.rho_inf {
        l.push(("rho_inf", f(d.rho_inf)));
    }
    if d.output_every != dflt.output_every {
        l.push(("output_every", d.output_every.to_string()));
    }
    if d.max_iterations != dflt.max_iterations {
        l.push(("max_iterations", d.max_iterations.to_string()));
    }
    push(&mut l, "initial_omega_rad_s", &d.initial_omega_rad_s, |v| {
        list(v)
    });
    if d.start_from_static {
        l.push(("start_from_static", "true".into()));
    }
    l
}

fn modes_lines(m: &ModesDeck) -> Lines {
    vec![
        ("count", m.count.to_string()),
        ("axis", list(&m.axis)),
        ("speeds_rad_s", list(&m.speeds_rad_s)),
    ]
}

fn write_lines(s: &mut String, lines: &Lines) {
    for (k, v) in lines {
        s.push_str(k);
        s.push_str(" = ");
        s.push_str(v);
        s.push('\n');
    }
}

fn write_comment(s: &mut String, lines: &[String]) {
    for c in lines {
        s.push_str("# ");
        s.push_str(c);
        s.push('\n');
    }
}

/// The layout's entries, then the items it does not list, table by table.
fn entries(d: &Deck) -> Vec<Entry> {
    let mut seen: Vec<Vec<bool>> = Kind::ALL.iter().map(|k| vec![false; k.count(d)]).collect();
    let slot = |k: Kind| Kind::ALL.iter().position(|a| *a == k).unwrap_or(0);
    let mut out = vec![];
    for e in &d.layout.entries {
        if let Some((k, i)) = e.item {
            match seen[slot(k)].get_mut(i) {
                Some(s) if !*s => *s = true,
                _ => continue,
            }
        }
        out.push(e.clone());
    }
    for (n, k) in Kind::ALL.iter().enumerate() {
        for (i, s) in seen[n].iter().enumerate() {
            if !s {
                out.push(Entry {
                    item: Some((*k, i)),
                    ..Default::default()
                });
            }
        }
    }
    out
}

/// The deck as TOML text, read back into an equal deck.
pub fn to_toml(d: &Deck) -> String {
    let mut s = String::new();
    write_comment(&mut s, &d.layout.header);
    let mut top = vec![];
    push(&mut top, "title", &d.title, |t| q(t));
    if d.gravity_m_s2 != [0.0; 3] {
        top.push(("gravity_m_s2", list(&d.gravity_m_s2)));
    }
    if !top.is_empty() {
        write_lines(&mut s, &top);
        s.push('\n');
    }
    for e in entries(d) {
        write_comment(&mut s, &e.comment);
        let Some((kind, i)) = e.item else {
            s.push('\n');
            continue;
        };
        let Some(mut lines) = item_lines(d, kind, i) else {
            continue;
        };
        if let Some(order) = e.keys {
            let rank = |k: &str| order.iter().position(|o| *o == k).unwrap_or(order.len());
            lines.sort_by_key(|(k, _)| rank(k));
        }
        s.push_str(&" ".repeat(e.indent));
        s.push_str(&format!("[[{}]]\n", kind.table()));
        write_lines(&mut s, &lines);
        s.push('\n');
    }
    for (name, lines) in [
        ("static", static_lines(&d.statics)),
        ("dynamic", dynamic_lines(&d.dynamic)),
        ("modes", modes_lines(&d.modes)),
    ] {
        if name != "static" {
            s.push('\n');
        }
        s.push_str(&format!("[{name}]\n"));
        write_lines(&mut s, &lines);
    }
    s
}

/// Items of generated decks: the keys a generator sets, the others absent.
impl NodeDeck {
    pub fn at(name: &str, position_m: [f64; 3]) -> Self {
        NodeDeck {
            name: name.into(),
            position_m,
            rotation_vector_rad: [0.0; 3],
        }
    }
}

impl BeamDeck {
    pub fn new(name: &str, elements: usize) -> Self {
        BeamDeck {
            name: name.into(),
            elements,
            start_m: None,
            end_m: None,
            arc: None,
            start_node: None,
            e2_direction: None,
            sections_csv: None,
            section: None,
            sections: None,
            damping_mu_s: None,
            twist_deg: None,
        }
    }
}

impl JointDeck {
    pub fn new(name: &str, kind: &str, node_a: Option<&str>, node_b: &str) -> Self {
        JointDeck {
            name: name.into(),
            kind: kind.into(),
            node_a: node_a.map(Into::into),
            node_b: node_b.into(),
            position_m: None,
            axis: None,
            x_direction: None,
            stiffness: None,
            damping: None,
            omega_rad_s: None,
            angle_table: None,
            displacement_m: None,
            displacement_table: None,
            stiffness_t: None,
            damping_t: None,
            stiffness_r: None,
            damping_r: None,
            locked: None,
            elastomer: None,
        }
    }
}

impl SensorDeck {
    pub fn at_node(name: &str, node: &str) -> Self {
        SensorDeck {
            name: name.into(),
            node: Some(node.into()),
            joint: None,
            beam: None,
            s_m: None,
        }
    }
    pub fn at_joint(name: &str, joint: &str) -> Self {
        SensorDeck {
            name: name.into(),
            node: None,
            joint: Some(joint.into()),
            beam: None,
            s_m: None,
        }
    }
}
