import bpy
settings = bpy.context.scene.topstoc

settings.target_mode = 'RATIO'
settings.ratio = 0.3
settings.quality = 'FAST'
settings.use_symmetry = True
settings.symmetry_axis = 'X'
settings.adaptivity = 0.5
settings.density = 'off'
settings.output = 'NEW_OBJECT'
