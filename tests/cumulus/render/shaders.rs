//! Every WGSL file in `shaders/` is parsed and validated by naga as part of
//! each pass module it belongs to, in every variant of the pass's `override`
//! constants; all failures are reported at once. Also checks the Rust uniform
//! structs against the WGSL layout naga computes.

use cumulus::config::RenderMethod;
use cumulus::gpu::pass::{PassSpec, Slots};
use cumulus::gpu::shaders::{assemble, prelude};
use cumulus::gpu::uniform::FrameUniform;
use cumulus::methods::raymarch::pack::{GpuParcel, GridUniform, ParcelsUniform};
use cumulus::methods::raymarch::passes::{self as raymarch, BAKED, EXACT};
use cumulus::methods::slices::gpu::passes as slices;
use cumulus::render::renderer::{modules, shader_files, slots};

fn parse(src: &str) -> Result<(naga::Module, naga::valid::ModuleInfo), String> {
    let module = naga::front::wgsl::parse_str(src).map_err(|e| e.emit_to_string(src))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .map_err(|e| e.emit_to_string(src))?;
    Ok((module, info))
}

/// All 2^n combinations of the pass's boolean overrides under `slots`.
fn variants(pass: &PassSpec, slots: &Slots) -> Vec<naga::back::PipelineConstants> {
    let names = pass.overrides(slots);
    (0..1u32 << names.len())
        .map(|bits| {
            names
                .iter()
                .enumerate()
                .map(|(i, n)| (n.to_string(), ((bits >> i) & 1) as f64))
                .collect()
        })
        .collect()
}

#[test]
fn every_pass_module_validates_in_every_variant() {
    let mut failures = Vec::new();
    let mut checked = 0;
    for (pass, method) in modules() {
        let src = pass.source(method);
        let (module, info) = match parse(&src) {
            Ok(m) => m,
            Err(e) => {
                failures.push(format!("{} ({}): {e}", pass.name, method.name));
                continue;
            }
        };
        for constants in variants(pass, method) {
            for ep in &module.entry_points {
                let r = naga::back::pipeline_constants::process_overrides(
                    &module,
                    &info,
                    Some((ep.stage, ep.name.as_str())),
                    &constants,
                );
                if let Err(e) = r {
                    failures.push(format!(
                        "{} ({}) {} {constants:?}: {e}",
                        pass.name, method.name, ep.name
                    ));
                }
                checked += 1;
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    // Every module of every method was checked, each in at least one
    // variant and entry point.
    assert!(checked >= modules().len(), "checked {checked}");
}

#[test]
fn every_file_in_shaders_dir_is_assembled() {
    fn wgsl_files(dir: &std::path::Path, prefix: &str, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let entry = entry.unwrap();
            let name = format!("{prefix}{}", entry.file_name().to_string_lossy());
            if entry.path().is_dir() {
                wgsl_files(&entry.path(), &format!("{name}/"), out);
            } else if name.ends_with(".wgsl") {
                out.push(name);
            }
        }
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk = Vec::new();
    wgsl_files(&dir, "", &mut on_disk);
    let files = shader_files();
    let missing: Vec<_> = on_disk
        .iter()
        .filter(|name| !files.iter().any(|(n, _)| n == name))
        .collect();
    assert!(missing.is_empty(), "in no file table: {missing:?}");
    for (name, _) in &files {
        // The bake makes its own pipelines (src/methods/raymarch/baked.rs).
        let used = *name == "raymarch/bake.wgsl"
            || modules().iter().any(|(p, s)| {
                p.assembly(s)
                    .is_ok_and(|a| a.files.iter().any(|f| f == name))
            });
        assert!(used, "{name} is in no pass module");
    }
}

/// Size of a named struct as naga lays it out.
fn wgsl_struct_size(module: &naga::Module, name: &str) -> u32 {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, _) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    layouter[handle].size
}

#[test]
fn rust_uniforms_match_wgsl_layout() {
    let src = raymarch::CLOUDS.source(&EXACT);
    let (module, _) = parse(&src).unwrap();
    assert_eq!(
        wgsl_struct_size(&module, "Frame") as usize,
        std::mem::size_of::<FrameUniform>()
    );
    assert_eq!(
        wgsl_struct_size(&module, "Parcel") as usize,
        std::mem::size_of::<GpuParcel>()
    );
    assert_eq!(
        wgsl_struct_size(&module, "Parcels") as usize,
        std::mem::size_of::<ParcelsUniform>()
    );
    assert_eq!(
        wgsl_struct_size(&module, "Grid") as usize,
        std::mem::size_of::<GridUniform>()
    );
    // The temporal uniform, declared by the march and the resolve alike.
    let temporal = std::mem::size_of::<cumulus::methods::raymarch::temporal::TemporalUniform>();
    assert_eq!(wgsl_struct_size(&module, "Temporal") as usize, temporal);
    let (resolve, _) = parse(&raymarch::TEMPORAL.source(&BAKED)).unwrap();
    assert_eq!(wgsl_struct_size(&resolve, "Temporal") as usize, temporal);
    // 16-byte fields only: no vec3 padding surprises.
    assert_eq!(std::mem::size_of::<FrameUniform>() % 16, 0);
    assert_eq!(std::mem::size_of::<GpuParcel>() % 16, 0);
}

#[test]
fn every_module_assembles_with_its_root_last() {
    for (pass, s) in modules() {
        let a = pass.assembly(s).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(a.files.last().map(String::as_str), Some(pass.root));
        // Every module starts with the prelude, then common.wgsl.
        assert!(a.source.starts_with(&prelude()));
        assert_eq!(a.files[0], "common.wgsl");
    }
}

/// Each file names what it uses: assembled with only its own imports
/// (under the slots of every method whose passes use it), it parses and
/// validates.
#[test]
fn every_file_stands_on_its_own_imports() {
    let files = shader_files();
    let mut failures = Vec::new();
    for (path, _) in &files {
        for m in RenderMethod::ALL {
            let s = slots(m);
            let used = modules().iter().any(|(p, t)| {
                t.name == p.slots_for(s).name
                    && p.assembly(t).unwrap().files.iter().any(|f| f == path)
            });
            if !used {
                continue;
            }
            let src = assemble(&files, path, s.bind, &prelude()).unwrap().source;
            if let Err(e) = parse(&src) {
                failures.push(format!("{path} ({m}): {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn slots_pick_each_method_s_files() {
    let files = |pass: &PassSpec, s: &Slots| pass.assembly(s).unwrap().files;
    let exact = files(&raymarch::CLOUDS, &EXACT);
    let baked = files(&raymarch::CLOUDS, &BAKED);
    assert!(exact.iter().any(|f| f == "raymarch/field_exact.wgsl"));
    assert!(exact.iter().any(|f| f == "raymarch/far_light_exact.wgsl"));
    assert!(!exact.iter().any(|f| f == "raymarch/field_baked.wgsl"));
    assert!(baked.iter().any(|f| f == "raymarch/field_baked.wgsl"));
    assert!(!baked.iter().any(|f| f.contains("exact")));
    let shadow = files(&cumulus::gpu::passes::SHADOW, &slices::SLOTS);
    assert!(shadow.iter().any(|f| f == "slices/shadow_field.wgsl"));
    assert!(!shadow.iter().any(|f| f.starts_with("raymarch/")));
    // The terrain under the sprites imports no method's field.
    let terrain = files(&cumulus::gpu::passes::TERRAIN, slots(RenderMethod::Sprites));
    assert!(!terrain.iter().any(|f| f.contains('/')), "{terrain:?}");
}

#[test]
fn overrides_come_from_the_modules() {
    use cumulus::gpu::passes::{SHADOW, SKY, TERRAIN};
    let mut clouds = raymarch::CLOUDS.overrides(&EXACT).to_vec();
    clouds.sort();
    assert_eq!(
        clouds,
        [
            "AERIAL_PERSPECTIVE",
            "ENCODE_SRGB",
            "GRID_CULLING",
            "HAS_TERRAIN",
            "MARCH_STEPS",
            "USE_NORMALS"
        ]
    );
    assert!(!raymarch::CLOUDS.declares(&BAKED, "GRID_CULLING"));
    assert!(SHADOW.declares(&EXACT, "GRID_CULLING"));
    assert!(TERRAIN.declares(&slices::SLOTS, "HAS_WATER"));
    assert!(!SKY.declares(&Slots::NONE, "AERIAL_PERSPECTIVE"));
    // Cached: the same slice each time.
    assert!(std::ptr::eq(
        SKY.overrides(&Slots::NONE),
        SKY.overrides(&Slots::NONE)
    ));
}

#[test]
#[should_panic(expected = "sky (none) declares no override HAS_TERRAIN")]
fn a_pipeline_key_takes_only_declared_constants() {
    use cumulus::gpu::pipelines::PipelineKey;
    let format = wgpu::TextureFormat::Rgba16Float;
    let sky = &cumulus::gpu::passes::SKY;
    PipelineKey::new(sky, &BAKED, &[], format);
    PipelineKey::new(sky, &BAKED, &[("HAS_TERRAIN", 1.0)], format);
}
