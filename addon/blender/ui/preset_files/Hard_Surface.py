import bpy
settings = bpy.context.scene.topstoc

settings.target_mode = 'RATIO'
settings.ratio = 0.3
settings.quality = 'FAST'
settings.use_symmetry = False
settings.adaptivity = 1.0
settings.density = 'off'
settings.output = 'NEW_OBJECT'
