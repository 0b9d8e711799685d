//! What `rotorsim expand` prints is what a run builds: for every shipped rotor deck (single
//! blade, whole rotor, hinged), the printed model deck reads back into a deck equal to the typed
//! one the run builds from, and both build the same model, number for number.
use rotorsim::flight::FlightRecord;
use rotorsim::rotor::expand::{
    expand_deck, expand_items, expand_rotor_deck, expand_rotor_items, Controls, ExpandOptions,
    HydraulicRef,
};
use rotorsim::rotor::hinged::{self, HingedExpand, HingedSpec};
use rotorsim::rotor::RotorDeck;
use rotorsim::solver::State;
use rotorsim::structure::deck::{build_deck, build_deck_ids, parse_deck, Deck};
use rotorsim::structure::deck_text::to_toml;
use rotorsim::structure::model::Model;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The shipped decks of `rotors/` and `docs/examples/`, sorted.
fn shipped() -> Vec<PathBuf> {
    let mut v = vec![];
    for dir in ["rotors", "docs/examples"] {
        for e in std::fs::read_dir(root().join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}

/// Everything a model holds, as text: nodes, elements, sensors, beams, border, initial state.
fn fingerprint(m: &Model) -> String {
    let nodes: Vec<String> = m
        .nodes
        .iter()
        .map(|n| format!("{} {:?} {:?}", n.name, n.x0, n.q0))
        .collect();
    let mut beams: Vec<_> = m.beams.iter().collect();
    beams.sort();
    let st = State::from_model(m);
    format!(
        "{nodes:?}\n{:?}\n{:?}\n{beams:?}\n{:?}\n{} step elements, {} distributed loads\n{:?} {:?} {:?}",
        m.elements,
        m.sensors,
        m.border_nodes,
        m.step_elements.len(),
        m.dist_loads.len(),
        st.x,
        st.q,
        st.lambda
    )
}

/// The printed deck reads back equal to `typed` and builds the same model.
fn check(typed: &Deck, file: &Path, what: &str) {
    let base = file.parent().unwrap();
    let text = to_toml(typed);
    let (parsed, from_text) = parse_deck(&text, what, base)
        .unwrap_or_else(|e| panic!("{what}: the printed deck does not read back: {e}"));
    assert_eq!(
        &parsed, typed,
        "{what}: the printed deck reads back different"
    );
    // without the generator's layout, the deck still prints into itself
    let (again, _) = parse_deck(&to_toml(&parsed), what, base).unwrap();
    assert_eq!(again, parsed, "{what}: the read deck prints different");
    let (from_typed, _) = build_deck(typed, what, base).unwrap();
    assert_eq!(from_typed.nodes.len(), from_text.nodes.len(), "{what}");
    assert_eq!(
        from_typed.elements.len(),
        from_text.elements.len(),
        "{what}"
    );
    assert!(
        fingerprint(&from_typed) == fingerprint(&from_text),
        "{what}: the models differ"
    );
}

/// The options `rotorsim expand` prints with (the damper table is the rotor deck's own).
fn options(path: &Path, deck: &RotorDeck, controls: Controls) -> ExpandOptions {
    let damper = deck.damper().unwrap();
    let name = path.file_name().unwrap().to_string_lossy();
    ExpandOptions {
        controls,
        table_revs: 2,
        hydraulic: Some(HydraulicRef {
            deck: name.to_string(),
            model: damper.model.name().into(),
            scheme: "rk4".into(),
            substeps: 25,
        }),
        speeds_rad_s: vec![0.0, deck.spec.rotor.omega_rad_s],
        ..Default::default()
    }
}

#[test]
fn every_shipped_rotor_deck_prints_the_model_it_runs() {
    let record = FlightRecord::read(&root().join("flightdata/c8534like.mcap")).unwrap();
    let flown = Controls::from_record(&record.meta.controls_deg);
    let mut checked = 0;
    for path in shipped() {
        let text = std::fs::read_to_string(&path).unwrap();
        if rotorsim::rotor::RotorKind::of_text(&text) == rotorsim::rotor::RotorKind::Hinged {
            let spec = HingedSpec::from_file(&path).unwrap();
            let name = path.display().to_string();
            check(
                &hinged::expand_deck(&spec, &HingedExpand::default()),
                &path,
                &name,
            );
            let decay = HingedExpand {
                lag_release_moment_nm: 100.0,
                lag_release_time_s: 0.01,
                hub_clamped: true,
                ..Default::default()
            };
            check(&hinged::expand_deck(&spec, &decay), &path, &name);
            checked += 1;
            continue;
        }
        let Ok(deck) = RotorDeck::from_file(&path) else {
            continue; // a structure deck
        };
        let specs: Vec<_> = (1..=deck.spec.rotor.blades)
            .map(|k| deck.blade(k).unwrap().spec)
            .collect();
        for controls in [Controls::default(), flown] {
            let opts = options(&path, &deck, controls);
            let name = format!("{} {controls:?}", path.display());
            check(&expand_deck(&deck.spec, &opts), &path, &name);
            check(&expand_rotor_deck(&specs, &opts), &path, &name);
            let linear = ExpandOptions {
                hydraulic: None,
                bearing_equivalent: true,
                lag_extra_k: 1.0e3,
                lag_extra_c: 10.0,
                ..opts
            };
            check(&expand_deck(&deck.spec, &linear), &path, &name);
            check(&expand_rotor_deck(&specs, &linear), &path, &name);
        }
        checked += 1;
    }
    assert!(checked >= 5, "only {checked} rotor decks found");
}

/// The ids the build returns for the parts a run drives and reads are the parts the names say.
#[test]
fn the_expansion_and_the_build_give_the_run_its_parts_by_id() {
    let path = root().join("rotors/uh60a_airframe.toml");
    let deck = RotorDeck::from_file(&path).unwrap();
    let specs: Vec<_> = (1..=deck.spec.rotor.blades)
        .map(|k| deck.blade(k).unwrap().spec)
        .collect();
    let opts = ExpandOptions {
        table_revs: 1,
        ..Default::default()
    };
    for (whole, (d, items)) in [
        (true, expand_rotor_items(&specs, &opts)),
        (false, expand_items(&deck.spec, &opts)),
    ] {
        let built = build_deck_ids(&d, "ids", path.parent().unwrap()).unwrap();
        let (m, ids) = (&built.model, &built.ids);
        let node = |i: usize| m.nodes[ids.nodes[i]].name.clone();
        assert_eq!(node(items.hub), "hub");
        assert_eq!(items.airframe.is_empty(), !whole);
        for &i in &items.airframe {
            assert!(node(i).starts_with("airframe."), "{}", node(i));
        }
        for (k, b) in items.blades.iter().enumerate() {
            let p = if whole {
                format!("b{}.", k + 1)
            } else {
                String::new()
            };
            assert_eq!(
                m.element_id(&format!("{p}swashplate_drive")),
                Some(ids.joints[b.swash])
            );
            assert_eq!(node(b.damper_ends[0]), format!("{p}damper_hub_end"));
            assert_eq!(node(b.damper_ends[1]), format!("{p}damper_blade_end"));
            let blade = &ids.beam_nodes[b.blade];
            let n = 3 * specs[k].blade.elements;
            assert_eq!(blade.len(), n + 1);
            assert_eq!(m.node_id(&format!("{p}blade.n0")).unwrap(), blade[0]);
            assert_eq!(m.node_id(&format!("{p}blade.n{n}")).unwrap(), blade[n]);
        }
    }
}
