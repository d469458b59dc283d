"""Blender 3.4's Mantaflow smoke on the scene of build/bin/BenchSmoke (docs/smoke.md): time per
frame and per Mantaflow step, and the last frame's density as OpenVDB for
measurements/smoke-side-by-side.py.

    blender -b --factory-startup -t 2 --python measurements/mantaflow-smoke-bench.py -- \
        RES FRAMES CACHE_DIR [--steps N | --cfl C] [--no-step-timing]

RES cells along each side of the 8 m cube, FRAMES frames of 1/24 s (BenchSmoke's
`frames`; Blender bakes frames 1 to FRAMES and steps frame 1 too, so cache frame f is
the state at f / 24 s, as Nimbus's frame f), CACHE_DIR a directory that does not exist
or is empty (one bake per process: run the script once per bake). `-t 2` gives Blender
(and Mantaflow's TBB) the 2 threads BenchSmoke uses by default; it must come before
--python.

Output: the bake's wall time per frame; the number of Mantaflow steps per frame and the
time inside them (Mantaflow's smoke step: emission, advection, vorticity, buoyancy,
pressure), the time Mantaflow spent writing its cache, and the rest (Blender: rasterising
the emitter mesh into the grid once per step, setting up, Python glue); then the path of
the last frame's .vdb (grids density, temperature, velocity, ...; "temperature" is
Mantaflow's heat, relative). The step count and times come from timers wrapped around
Mantaflow's own Python step and cache-saving functions (see StepTimer; a few
microseconds per step); --no-step-timing leaves them out and reports the wall time only.

The scene, BenchSmoke's (Benchmarks/BenchSmoke.cxx) in Blender's terms:
  domain      a cube of 8 m from (-4, -4, 0) to (4, 4, 8), resolution_max RES (cells of
              8/RES m); no adaptive domain, no noise (high-resolution) pass; walls on the
              four sides and the bottom, the top open (Nimbus: the same, but Mantaflow's
              walls take the outermost layer of cells, Nimbus's are the box's faces);
  emitter     a UV sphere of radius 0.75 m at (0, 0, 0.75), smoke, inflow, emitting from
              its whole volume (volume_density 1, surface_distance 0; Blender's default
              emits from a 1.5-cell band around the surface only);
  density     Nimbus adds 2 per second inside the sphere; here additive emission
              (use_absolute off) of 2 / (24 N) per step (N steps per frame): the same
              rate, but Blender clamps the emitted cells at 1 (Nimbus does not clamp);
  buoyancy    Nimbus: g (T - T_amb) / T_amb = 1.047 g in 600 K smoke at 293.15 K ambient,
              none from the density. Mantaflow adds g * beta * heat / L per unit heat
              (L: the domain's longest side, 8 m; smoke_script's buoyancy_heat =
              beta / domain size), so beta 5 (its maximum) and heat 1.047 * 8 / 5 = 1.675
              give the same acceleration; alpha (density buoyancy) 0;
  vorticity   Nimbus adds eps h (N x omega) dt per sub-step (eps 0.3); Mantaflow adds
              strength h (N x omega) per step, without dt (extforces.cpp, KnConfForce),
              so strength = 0.3 / (24 N) with N steps per frame;
  time        24 frames per second; --steps N (default 1): exactly N Mantaflow steps per
              frame (adaptive stepping on with timesteps_min = timesteps_max = N, which
              pins dt to a frame / N). --cfl C: Blender's adaptive stepping with CFL
              number C and 1 to 100 steps per frame (Nimbus sub-steps at CFL 2: --cfl 2
              is its peer); the emission and vorticity are then set for 1 step per frame
              and are stronger per frame when Mantaflow takes more.
What differs and cannot be matched:
  - Mantaflow writes its cache (OpenVDB, Blender's default 16-bit floats with Blosc) after
    every frame, inside the bake; Nimbus keeps everything in memory. Reported apart.
  - Mantaflow solves pressure by conjugate gradients with a multigrid preconditioner
    (PcMGStatic) until the largest residual is 1e-3 in its grid units, at most 1.5 x the
    grid's side iterations (solvePressure's defaults; Blender passes neither); Nimbus by
    conjugate gradients with incomplete Cholesky to a relative residual of 1e-7: a much
    tighter solve, many more iterations.
  - Nimbus's smoke cools (0.2 per second) and has a Smagorinsky eddy viscosity (0.15);
    Mantaflow's heat never cools (without dissolve) and smoke has no viscosity.
  - Advection: both MacCormack (Mantaflow's advectSemiLagrange order 2, clamped), but
    Blender also re-rasterises the emitter mesh every step (Nimbus: an analytic sphere).
  - Blender's density in emitter cells is clamped at 1.
Checked at 32^3 against vtkNimbusSmokeSource with these parameters (frames 1, 6, 12, 18,
24): the same top of the plume (density > 0.05) at every frame, the largest speed within
3 to 13 % (6.4 against 5.7 m/s at frame 24), the smoke's centroid within 0.07 m, its
amount 10 to 25 % lower (the clamp at 1 and the wall layer under the emitter).
The .vdb's transform is a pure scale (voxel size 8/RES m, index (0, 0, 0) at the origin):
world = domain corner (-4, -4, 0) + (index + 0.5) * voxel size for cell centres, which
measurements/smoke-side-by-side.py applies.

Why 64^3 bakes used to stop with "'NoneType' object has no attribute 'getDataPointer'"
(and sometimes 32^3 ones too): the bake never started. Every bpy.ops call first updates
the depsgraph; when the fluid domain is evaluated with cache type ALL or MODULAR before
the flow object exists, and then again with the flow (here: at the update bake_all does
before it runs), Blender activates the heat grid for the flow and asks Mantaflow for its
pointer while Mantaflow's Python side never allocated it (heat_s<id> and heatIn_s<id>
are still None). The Python error is left pending and bpy.ops raises it. With a threaded
depsgraph it happened in about 3 of 4 runs at any resolution (8 of 8 with
--debug-depsgraph-no-threads), so one run could pass and the next fail: it was never
about 64^3 or the cache directory.
The fix: create the flow object before the domain (and set the cache type last), then
update the depsgraph once, checked, before the bake.
"""
import argparse
import collections
import glob
import os
import sys
import time

import bpy

#The scene of Testing / Benchmarks / BenchSmoke.cxx.
DOMAIN_SIZE = 8.0                 # m, cube
DOMAIN_MIN = (-4.0, -4.0, 0.0)    # m
EMITTER_CENTRE = (0.0, 0.0, 0.75)  # m
EMITTER_RADIUS = 0.75             # m
DENSITY_PER_SECOND = 2.0
EMITTER_KELVIN = 600.0
AMBIENT_KELVIN = 293.15
VORTICITY = 0.3                   # Nimbus's eps (per second)
FPS = 24
BETA = 5.0                        # Blender's maximum heat buoyancy


def fail(message):
    print(f"mantaflow-smoke-bench: {message}", file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(1)  # Blender would otherwise go on and exit 0


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="mantaflow-smoke-bench.py",
                                     description="Mantaflow's peer of BenchSmoke")
    parser.add_argument("res", type=int, help="cells along each side")
    parser.add_argument("frames", type=int, help="frames of 1/24 s to simulate")
    parser.add_argument("cache", help="cache directory: absent or empty")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--steps", type=int, default=None,
                      help="Mantaflow steps per frame, fixed (default 1)")
    mode.add_argument("--cfl", type=float, default=None,
                      help="adaptive steps with this CFL number (1 to 100 per frame)")
    parser.add_argument("--no-step-timing", action="store_true",
                        help="no step timers: wall time only")
    args = parser.parse_args(argv)
    if args.res < 8 or args.res > 1024:
        parser.error("res must be in [8, 1024]")
    if args.frames < 1:
        parser.error("frames must be >= 1")
    if args.steps is not None and not 1 <= args.steps <= 100:
        parser.error("--steps must be in [1, 100]")
    if args.cfl is not None and not 0.0 < args.cfl <= 10.0:
        parser.error("--cfl must be in (0, 10]")
    return args


def build_scene(args):
    cache = os.path.abspath(args.cache)
    if os.path.exists(cache) and (not os.path.isdir(cache) or os.listdir(cache)):
        fail(f"{cache} exists and is not an empty directory: give a fresh one per bake")
    os.makedirs(cache, exist_ok=True)
    steps = 1 if args.steps is None else args.steps
    last_frame = args.frames  # Blender steps frame 1 too: frame f is the state at f / 24 s

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = FPS
    scene.render.fps_base = 1.0
    scene.frame_start = 1
    scene.frame_end = last_frame
    scene.frame_current = 1
    scene.use_gravity = True
    scene.gravity = (0.0, 0.0, -9.81)

#The flow object first : a domain evaluated(every bpy.ops call updates the
#depsgraph) before its flow exists breaks the bake(see the header).
    bpy.ops.mesh.primitive_uv_sphere_add(radius=EMITTER_RADIUS, location=EMITTER_CENTRE,
                                         segments=64, ring_count=32)
    flow = bpy.context.active_object
    flow.name = "Emitter"
    fm = flow.modifiers.new("Fluid", "FLUID")
    fm.fluid_type = "FLOW"
    fs = fm.flow_settings
    fs.flow_type = "SMOKE"
    fs.flow_behavior = "INFLOW"
    fs.flow_source = "MESH"
    fs.volume_density = 1.0
    fs.surface_distance = 0.0
    fs.use_absolute = False
    fs.density = DENSITY_PER_SECOND / (FPS * steps)
    heat = (EMITTER_KELVIN - AMBIENT_KELVIN) / AMBIENT_KELVIN * DOMAIN_SIZE / BETA
    fs.temperature = heat
    fs.use_initial_velocity = False
    fs.subframes = 0

    bpy.ops.mesh.primitive_cube_add(size=DOMAIN_SIZE, location=(
        DOMAIN_MIN[0] + DOMAIN_SIZE / 2, DOMAIN_MIN[1] + DOMAIN_SIZE / 2,
        DOMAIN_MIN[2] + DOMAIN_SIZE / 2))
    domain = bpy.context.active_object
    domain.name = "Domain"
    mod = domain.modifiers.new("Fluid", "FLUID")
    mod.fluid_type = "DOMAIN"
    ds = mod.domain_settings
    ds.domain_type = "GAS"
    ds.resolution_max = args.res
    ds.use_adaptive_domain = False
    ds.use_noise = False
    ds.use_dissolve_smoke = False
    ds.alpha = 0.0
    ds.beta = BETA
    ds.vorticity = VORTICITY / (FPS * steps)
    ds.time_scale = 1.0
    for side in ("front", "back", "left", "right", "bottom"):
        setattr(ds, f"use_collision_border_{side}", True)
    ds.use_collision_border_top = False
    ds.use_adaptive_timesteps = True
    if args.cfl is None:
        ds.timesteps_min = steps
        ds.timesteps_max = steps
    else:
        ds.cfl_condition = args.cfl
        ds.timesteps_min = 1
        ds.timesteps_max = 100
    ds.cache_directory = cache
    ds.cache_data_format = "OPENVDB"
    ds.cache_frame_start = 1
    ds.cache_frame_end = last_frame
    ds.cache_type = "ALL"  # last, with the flow already there
    bpy.context.view_layer.objects.active = domain
    for o in bpy.context.view_layer.objects:
        o.select_set(o is domain)
#One checked update : a Mantaflow error left pending here would otherwise surface
#as the exception of bake_all's own update and no bake.
    try:
        bpy.context.view_layer.update()
    except Exception as e:  # noqa: BLE001
        fail(f"Blender's depsgraph update failed before the bake: {e!r} "
             f"(cause: {e.__cause__!r})")
    return domain, ds, cache, steps, last_frame, heat


class StepTimer:
    """Counts and times Mantaflow's own Python functions during the bake.

    Mantaflow runs its Python (smoke_adaptive_step_<id>, smoke_save_data_<id>, ...) in
    its own module, on whichever thread the depsgraph evaluates the domain (often not
    this one, so a sys.setprofile hook misses steps). Its scripts start with
    `from manta import *`, so a wrapper put on manta.mantaMsg before the bake is what
    they call; at 'Bake fluid data' (the first line of every frame's bake, before the
    step) it wraps the step and save functions of the caller's module with timers."""

    STEP = "smoke_adaptive_step_"
    SAVES = ("smoke_save_data_", "fluid_save_data_")

    def __init__(self):
        import manta  # Blender's built-in Mantaflow module
        self.manta = manta
        self.original = manta.mantaMsg
        self.steps = collections.Counter()  # frame -> steps
        self.step_seconds = 0.0
        self.save_seconds = 0.0
        self.wrapped = 0

        def message(*args, **kwargs):
            if args and args[0] == "Bake fluid data":
                self.wrap(sys._getframe(1).f_globals)
            return self.original(*args, **kwargs)
        manta.mantaMsg = message

    def wrap(self, namespace):
        for name, function in list(namespace.items()):
            if not callable(function) or getattr(function, "_nimbus_timed", False):
                continue
            if name.startswith(self.STEP):
                namespace[name] = self.timed(function, step=True)
            elif name.startswith(self.SAVES):
                namespace[name] = self.timed(function, step=False)

    def timed(self, function, step):
        def call(*args, **kwargs):
            start = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                seconds = time.perf_counter() - start
                if step:
                    self.steps[args[0] if args else kwargs.get("framenr")] += 1
                    self.step_seconds += seconds
                else:
                    self.save_seconds += seconds
        call._nimbus_timed = True
        self.wrapped += 1
        return call

    def close(self):
        self.manta.mantaMsg = self.original


def main():
    args = parse()
    domain, ds, cache, steps, last_frame, heat = build_scene(args)
    mode = (f"{steps} step(s) per frame, fixed" if args.cfl is None
            else f"adaptive, CFL {args.cfl:g}, 1-100 steps per frame")
    print(f"MANTAFLOW scene: {args.res}^3 cells of {DOMAIN_SIZE / args.res:.4f} m, "
          f"{args.frames} frames at {FPS} fps, {mode}; "
          f"heat {heat:.4f} x beta {BETA:g}, vorticity {ds.vorticity:.5f} per step, "
          f"density {DENSITY_PER_SECOND / (FPS * steps):.5f} per step; "
          f"{bpy.context.scene.render.threads} threads (blender -t)")
    timer = None if args.no_step_timing else StepTimer()
    start = time.perf_counter()
    try:
        result = bpy.ops.fluid.bake_all()
    except Exception as e:  # noqa: BLE001
        fail(f"bake_all raised {e!r} (cause: {e.__cause__!r})")
    finally:
        if timer:
            timer.close()
    elapsed = time.perf_counter() - start

#Did Mantaflow bake every frame ?
    data = os.path.join(cache, "data")
    files = sorted(glob.glob(os.path.join(data, "fluid_data_*.vdb")))
    expected = [os.path.join(data, f"fluid_data_{f:04d}.vdb") for f in range(1, last_frame + 1)]
    missing = [p for p in expected if not os.path.isfile(p)]
    if "FINISHED" not in result or missing:
        fail(f"Mantaflow baked {len(files)} of {last_frame} frames into {data} "
             f"(bake_all returned {set(result)}; first missing: "
             f"{os.path.basename(missing[0]) if missing else 'none'})")
    if timer and sum(timer.steps.values()) == 0:
        fail("the bake wrote files but no Mantaflow step was seen: step timing broken")

    frames = args.frames
    print(f"MANTAFLOW res {args.res} frames {frames}: bake {elapsed:.2f} s, "
          f"{elapsed / frames * 1000:.1f} ms per frame (wall, cache writes included)")
    if timer:
        total = sum(timer.steps.values())
        per_frame = [timer.steps[f] for f in sorted(k for k in timer.steps if k is not None)]
        other = elapsed - timer.step_seconds - timer.save_seconds
        print(f"MANTAFLOW steps: {total} in {frames} frames "
              f"({total / frames:.2f} per frame; per frame: "
              f"{' '.join(str(n) for n in per_frame)})")
        print(f"MANTAFLOW time: steps {timer.step_seconds:.2f} s "
              f"({timer.step_seconds / frames * 1000:.1f} ms per frame, "
              f"{timer.step_seconds / total * 1000:.1f} ms per step, "
              f"{timer.step_seconds / (total * args.res ** 3) * 1e9:.1f} ns per cell-step); "
              f"cache writes {timer.save_seconds:.2f} s "
              f"({timer.save_seconds / frames * 1000:.1f} ms per frame); "
              f"rest (emitter rasterisation, setup) {other:.2f} s "
              f"({other / frames * 1000:.1f} ms per frame)")
    print(f"MANTAFLOW last frame: {expected[-1]}")


main()
