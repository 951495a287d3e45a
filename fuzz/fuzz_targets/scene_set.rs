//! Fuzzes `--set KEY=VALUE` edits on the built-in scenes: the first byte picks a scene, the rest is one
//! edit per line. Applying the edits and resolving the scene must never panic; a refused scene must say
//! why (never the fallback `UNEXPLAINED`); an accepted one must read back to itself from its stored TOML.
#![no_main]

use coin_log::scene::{self, presets, FlagOverrides, SceneError, UNEXPLAINED};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let name = presets::NAMES[usize::from(pick) % presets::NAMES.len()];
    let Some(preset) = presets::preset(name) else {
        return;
    };
    let sets: Vec<String> = text.lines().map(str::to_string).collect();
    let Ok(file) = scene::file_with_sets(&preset, &sets) else {
        return;
    };
    match scene::resolve(&file, &FlagOverrides::default()) {
        Err(SceneError::Invalid(problems)) => {
            assert!(
                problems.iter().all(|p| p.reason != UNEXPLAINED),
                "{name} {sets:?}: refused without a reason: {problems}"
            );
        }
        Err(_) => {}
        Ok(scene) => {
            let written = scene.to_toml();
            let back = scene::parse_with_sets(&written, &[])
                .map_err(|e| e.to_string())
                .and_then(|f| scene::Scene::from_file(&f).map_err(|e| e.to_string()));
            assert_eq!(back.as_ref(), Ok(&scene), "{name} {sets:?}; stored scene:\n{written}");
        }
    }
});
