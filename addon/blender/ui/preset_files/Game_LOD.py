import bpy
settings = bpy.context.scene.topstoc

settings.target_mode = 'RATIO'
settings.ratio = 0.25
settings.quality = 'QUALITY'
settings.use_symmetry = False
settings.adaptivity = 0.5
settings.density = 'off'
settings.output = 'NEW_OBJECT'
