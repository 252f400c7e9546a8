//! A render is a pure function of (scene, seed, spp): the same on 1 thread and on many, and
//! the same whether the samples come in one pass or several.

use twinpath::cpu::CpuRenderer;
use twinpath::film::Film;
use twinpath::scene::SceneFile;

fn render(scene: &SceneFile, passes: &[u32]) -> Film {
    let cpu = CpuRenderer::new(&scene.scene, &scene.settings);
    let mut film = Film::new(scene.scene.camera.width, scene.scene.camera.height);
    let mut first = 0;
    for &n in passes {
        cpu.render_into(&scene.params(first, n), first, n, &mut film, None);
        first += n;
    }
    film
}

#[test]
fn same_image_for_any_thread_count_and_pass_split() {
    let mut scene = SceneFile::builtin_default();
    scene.scene.camera.width = 64;
    scene.scene.camera.height = 48;
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| render(&scene, &[4]));
    let four = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .unwrap();
    let b = four.install(|| render(&scene, &[4]));
    let c = four.install(|| render(&scene, &[1, 3]));
    assert_eq!(a.mean(), b.mean());
    // Summation in f64 of the same samples in the same order per pixel: identical.
    assert_eq!(a.mean(), c.mean());
    // And a different seed gives a different image.
    scene.settings.seed += 1;
    let d = render(&scene, &[4]);
    assert_ne!(a.mean(), d.mean());
}
