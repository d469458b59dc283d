"""Blender 3.4's Mantaflow smoke at a given resolution: the peer of build/bin/BenchSmoke
(issue 17). The same scene: an 8 m cube domain, a smoke inflow sphere of radius 0.75 m at
(0, 0, 0.75), vorticity 0.3, no noise, 24 frames per second.

    blender -b --factory-startup --python scripts/mantaflow-smoke-bench.py -- RES FRAMES CACHE_DIR

Prints the bake's seconds and the time per frame. The bake writes Mantaflow's cache to
CACHE_DIR (its time is part of what a Blender user waits for) and takes 1 to 4 adaptive
time steps per frame.
"""
import bpy
import sys
import time
argv = sys.argv[sys.argv.index("--") + 1:]
res, frames, cache = int(argv[0]), int(argv[1]), argv[2]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.frame_start = 1
scene.frame_end = frames
bpy.ops.mesh.primitive_cube_add(size=8, location=(0, 0, 4))
domain = bpy.context.active_object
mod = domain.modifiers.new("Fluid", "FLUID")
mod.fluid_type = "DOMAIN"
ds = mod.domain_settings
ds.domain_type = "GAS"
ds.resolution_max = res
ds.cache_directory = cache
ds.cache_type = "ALL"
ds.use_adaptive_domain = False
ds.vorticity = 0.3
ds.use_noise = False
ds.timesteps_max = 4
ds.timesteps_min = 1
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.75, location=(0, 0, 0.75))
flow = bpy.context.active_object
fm = flow.modifiers.new("Fluid", "FLUID")
fm.fluid_type = "FLOW"
fs = fm.flow_settings
fs.flow_type = "SMOKE"
fs.flow_behavior = "INFLOW"
fs.temperature = 1.0
bpy.context.view_layer.objects.active = domain
domain.select_set(True)
start = time.perf_counter()
bpy.ops.fluid.bake_all()
elapsed = time.perf_counter() - start
print(f"MANTAFLOW res {res} frames {frames}: {elapsed:.2f} s, {elapsed / frames * 1000:.1f} ms per frame")
