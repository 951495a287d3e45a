//! What Foxglove needs from a recording (format.md: Frames and Foxglove output): the frame tree world → table → coin (one
//! parent each, no cycle, each transform published before a scene update uses its frame), the cylinder in
//! `coin`, the track in `table`, Foxglove timestamps equal to log times, `/scene` at ≈ 30 per time unit,
//! and the shipped layout (`/scene` visible, following `world`, the plots on numeric fields).

// Helpers outside #[test] functions panic on any failure by design.
#![allow(clippy::unwrap_used)]

use crate::support::record::read_messages;
use crate::support::writers::{record_circle, Damage};
use crate::support::{dataset_files, repo};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};

/// (topic, log time, message) of every message of a file.
type Messages = Vec<(String, u64, Value)>;

fn time_ns(stamp: &Value) -> u64 {
    stamp["sec"].as_u64().unwrap() * 1_000_000_000 + stamp["nsec"].as_u64().unwrap()
}

/// A recording of `duration` time units at 100 samples per time unit, read back.
fn recording(duration: f64) -> Vec<(String, u64, Value)> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("circle.mcap");
    record_circle(&path, duration, Damage::None);
    read_messages(&path)
}

/// The committed recordings (made by `coin-log record`), read back, with their names.
fn datasets() -> Vec<(String, Messages)> {
    dataset_files()
        .into_iter()
        .map(|p| (p.display().to_string(), read_messages(&p)))
        .collect()
}

/// A fresh 2-time-unit recording and every committed dataset.
fn recordings() -> Vec<(String, Messages)> {
    let mut all = vec![("fresh circle".to_string(), recording(2.0))];
    all.extend(datasets());
    all
}

#[test]
fn the_frames_form_the_tree_world_table_coin_with_one_parent_each() {
    for (name, messages) in recordings() {
        println!("{name}:");
        check_frame_tree(&messages);
    }
}

fn check_frame_tree(messages: &[(String, u64, Value)]) {
    let mut parents: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut first_seen: BTreeMap<String, u64> = BTreeMap::new();
    for (topic, lt, v) in messages {
        if topic == "/tf" {
            let child = v["child_frame_id"].as_str().unwrap().to_string();
            let parent = v["parent_frame_id"].as_str().unwrap().to_string();
            assert_ne!(child, parent, "a frame is its own parent");
            first_seen.entry(child.clone()).or_insert(*lt);
            parents.entry(child).or_default().insert(parent);
        }
    }
    println!("  parents: {parents:?}");
    let expected: BTreeMap<String, BTreeSet<String>> = [
        ("table".to_string(), BTreeSet::from(["world".to_string()])),
        ("coin".to_string(), BTreeSet::from(["table".to_string()])),
    ]
    .into();
    assert_eq!(parents, expected, "world → table → coin, one parent each");
    // No cycle: walking up from every frame reaches the root `world`, which has no parent.
    for start in parents.keys() {
        let mut frame = start.clone();
        let mut steps = 0;
        while let Some(p) = parents.get(&frame) {
            frame = p.iter().next().unwrap().clone();
            steps += 1;
            assert!(steps <= parents.len(), "cycle above {start}");
        }
        assert_eq!(frame, "world");
    }
    // The static transform once, at t = 0, before the first scene update.
    let table_tfs = messages
        .iter()
        .filter(|(t, _, v)| t == "/tf" && v["child_frame_id"] == "table")
        .count();
    assert_eq!(table_tfs, 1, "world → table published once");
    let first_scene = messages.iter().position(|(t, _, _)| t == "/scene").unwrap();
    let first_table = messages
        .iter()
        .position(|(t, _, v)| t == "/tf" && v["child_frame_id"] == "table")
        .unwrap();
    let first_coin = messages
        .iter()
        .position(|(t, _, v)| t == "/tf" && v["child_frame_id"] == "coin")
        .unwrap();
    assert!(first_table < first_scene && first_coin < first_scene);
    let t0 = messages[0].1;
    assert_eq!(first_seen["table"], t0);
    assert_eq!(first_seen["coin"], t0);
}

#[test]
fn the_coin_is_a_cylinder_in_the_coin_frame_and_the_track_lies_in_the_table_frame() {
    for (name, messages) in datasets() {
        let (scenes, points) = check_scene_entities(&messages);
        println!("{name}: {scenes} scene updates, {points} track points");
        assert!(scenes > 0);
    }
    let (scenes, track_points) = check_scene_entities(&recording(2.0));
    println!("{scenes} scene updates, {track_points} new track points (expected 200: one per sample after the first)");
    assert_eq!(track_points, 200);
}

/// Checks every scene entity; returns (scene updates, new track points).
fn check_scene_entities(messages: &[(String, u64, Value)]) -> (usize, usize) {
    let mut track_points = 0;
    let mut scenes = 0;
    for (topic, _, v) in messages.iter().filter(|(t, _, _)| t == "/scene") {
        assert_eq!(topic, "/scene");
        scenes += 1;
        for e in v["entities"].as_array().unwrap() {
            let id = e["id"].as_str().unwrap();
            match id {
                "coin" => {
                    assert_eq!(e["frame_id"], "coin");
                    assert_eq!(e["cylinders"].as_array().unwrap().len(), 1);
                    assert_eq!(e["frame_locked"], true);
                }
                "table" => assert_eq!(e["frame_id"], "table"),
                _ => {
                    assert!(id.starts_with("track-"), "unexpected entity {id}");
                    assert_eq!(e["frame_id"], "table");
                    let line = &e["lines"][0];
                    assert_eq!(line["type"], 0);
                    let points = line["points"].as_array().unwrap();
                    assert!(points.len() >= 2);
                    // On the table plane y = 0 of the note's frame.
                    assert!(points.iter().all(|p| p["y"].as_f64() == Some(0.0)));
                    track_points += points.len() - 1;
                }
            }
        }
    }
    (scenes, track_points)
}

#[test]
fn every_foxglove_timestamp_equals_its_log_time() {
    let mut checked = 0;
    for (topic, lt, v) in recordings().iter().flat_map(|(_, m)| m) {
        let stamps: Vec<&Value> = match topic.as_str() {
            "/tf" => vec![&v["timestamp"]],
            "/scene" => v["entities"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| &e["timestamp"])
                .collect(),
            _ => vec![],
        };
        for s in stamps {
            assert_eq!(time_ns(s), *lt, "{topic}: {s} vs log time {lt}");
            assert!(s["nsec"].as_u64().unwrap() < 1_000_000_000);
            checked += 1;
        }
    }
    println!("{checked} timestamps equal to their log time");
    assert!(checked > 200);
}

#[test]
fn scene_updates_come_at_about_thirty_per_time_unit() {
    let duration = 5.0;
    let messages = recording(duration);
    let times: Vec<u64> = messages
        .iter()
        .filter(|(t, _, _)| t == "/scene")
        .map(|(_, lt, _)| *lt)
        .collect();
    #[allow(clippy::cast_precision_loss)]
    let rate = (times.len() - 1) as f64 / duration;
    let max_gap = times.windows(2).map(|w| w[1] - w[0]).max().unwrap();
    println!(
        "/scene: {} updates, {rate} per time unit (expected 30 ± 1), largest gap {max_gap} ns (≤ 4e7)",
        times.len()
    );
    assert!((rate - 30.0).abs() <= 1.0);
    assert!(max_gap <= 40_000_000);
    assert_eq!(
        *times.last().unwrap(),
        5_000_000_000,
        "the last sample has a scene update"
    );
}

fn layout() -> Value {
    let text = std::fs::read_to_string(repo().join("datasets/foxglove-layout.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Panel ids in a layout tree (a string, or {first, second, direction, ...}).
fn panel_ids(node: &Value, out: &mut Vec<String>) {
    match node {
        Value::String(id) => out.push(id.clone()),
        Value::Object(o) => {
            panel_ids(&o["first"], out);
            panel_ids(&o["second"], out);
        }
        _ => panic!("bad layout node {node}"),
    }
}

#[test]
fn the_layout_shows_the_scene_following_world_and_plots_the_main_quantities() {
    let layout = layout();
    for key in [
        "configById",
        "globalVariables",
        "userNodes",
        "playbackConfig",
        "layout",
    ] {
        assert!(layout.get(key).is_some(), "layout lacks `{key}`");
    }
    let configs = layout["configById"].as_object().unwrap();
    let mut ids = Vec::new();
    panel_ids(&layout["layout"], &mut ids);
    let in_tree: BTreeSet<&String> = ids.iter().collect();
    let configured: BTreeSet<&String> = configs.keys().collect();
    assert_eq!(
        in_tree, configured,
        "every panel in the tree is configured and vice versa"
    );

    let three_d: Vec<&Value> = configs
        .iter()
        .filter(|(id, _)| id.starts_with("3D!"))
        .map(|(_, c)| c)
        .collect();
    assert_eq!(three_d.len(), 1, "one 3D panel");
    let c = three_d[0];
    assert_eq!(c["followTf"], "world");
    assert_eq!(
        c["topics"]["/scene"]["visible"], true,
        "SceneUpdate topics are hidden by default"
    );
    assert_eq!(c["topics"]["/tf"]["visible"], true);

    let mut paths = BTreeSet::new();
    for (id, c) in configs {
        if id.starts_with("Plot!") {
            for p in c["paths"].as_array().unwrap() {
                assert_eq!(p["enabled"], true);
                paths.insert(p["value"].as_str().unwrap().to_string());
            }
        } else {
            assert!(id.starts_with("3D!"), "unexpected panel {id}");
        }
    }
    let wanted = [
        "/coin/omega.x",
        "/coin/omega.y",
        "/coin/omega.z",
        "/coin/angles.theta",
        "/coin/energy.total",
        "/coin/reaction.normal",
    ];
    for w in wanted {
        assert!(paths.contains(w), "no plot of {w}");
    }
    // Each plotted path ends on a numeric field of its topic's schema.
    for p in &paths {
        let (topic, field) = p.split_once('.').unwrap();
        let channel = coin_log::format::Channel::from_topic(topic)
            .unwrap_or_else(|| panic!("{p}: unknown topic"));
        let schema: Value =
            serde_json::from_slice(coin_log::format::schema_bytes(channel.schema_name()).unwrap())
                .unwrap();
        assert_eq!(
            schema["properties"][field]["type"],
            "number",
            "{p}: not a number field of {}",
            channel.schema_name()
        );
    }
    println!("plotted: {paths:?}");
}
