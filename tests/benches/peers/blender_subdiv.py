"""Blender peer of the speed comparison: import a .glb, apply a Subdivision Surface modifier
(Catmull-Clark) at a level, export a .glb with normals and texture coordinates.

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P blender_subdiv.py -- IN.glb OUT.glb LEVEL

Catmull-Clark turns each triangle into 3 quads and each further level multiplies by 4; the
exporter splits quads in two, so a level-4 result has 6 * 4^3 = 384 triangles per input one.
"""
import sys

import bpy
import numpy

# Debian's Blender 3.4 glTF importer still uses numpy.bool, which the numpy Debian ships with it
# (1.24) no longer has.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:]
if len(args) != 3:
    sys.exit(__doc__)
source, target, level = args[0], args[1], int(args[2])

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=source)
for obj in [o for o in bpy.context.scene.objects if o.type == "MESH"]:
    bpy.context.view_layer.objects.active = obj
    for other in bpy.context.scene.objects:
        other.select_set(other is obj)
    # Smooth shading from the subdivided surface, not the imported per-corner normals.
    if obj.data.has_custom_normals:
        bpy.ops.mesh.customdata_custom_splitnormals_clear()
    obj.data.use_auto_smooth = False
    bpy.ops.object.shade_smooth()
    modifier = obj.modifiers.new("Subdivision", "SUBSURF")
    modifier.subdivision_type = "CATMULL_CLARK"
    modifier.levels = modifier.render_levels = level
    bpy.ops.object.modifier_apply(modifier=modifier.name)
bpy.ops.export_scene.gltf(
    filepath=target,
    export_format="GLB",
    export_normals=True,
    export_texcoords=True,
    export_materials="EXPORT",
    export_draco_mesh_compression_enable=False,
)
