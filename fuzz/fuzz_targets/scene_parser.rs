//! Fuzzes the scene parser and validation with arbitrary TOML text (TOML → `SceneFile` → `Scene`): it must
//! never panic; a refused scene must say why (never the fallback `UNEXPLAINED`); an accepted scene must
//! respect the limits that make a recording safe, and read back to itself from the TOML it stores.
#![no_main]

use coin_log::scene::{self, limits, Scene, SceneError, UNEXPLAINED};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(file) = scene::parse_with_sets(text, &[]) else {
        return;
    };
    check(Scene::from_file(&file));
});

/// The properties of a resolved scene, or of a refusal.
fn check(result: Result<Scene, SceneError>) {
    match result {
        Err(SceneError::Invalid(problems)) => {
            assert!(
                problems.iter().all(|p| p.reason != UNEXPLAINED),
                "refused without a reason: {problems}"
            );
        }
        Err(_) => {}
        Ok(scene) => {
            let run = &scene.run;
            assert!(run.rate <= limits::max_rate(run.duration), "{run:?}");
            assert!(scene.initial.is_finite(), "{:?}", scene.initial);
            let written = scene.to_toml();
            let back = scene::parse_with_sets(&written, &[])
                .map_err(|e| e.to_string())
                .and_then(|f| Scene::from_file(&f).map_err(|e| e.to_string()));
            assert_eq!(back.as_ref(), Ok(&scene), "stored scene:\n{written}");
        }
    }
}
