import bpy
settings = bpy.context.scene.topstoc

settings.target_mode = 'RATIO'
settings.ratio = 0.05
settings.quality = 'QUALITY'
settings.use_symmetry = False
settings.adaptivity = 0.7
settings.density = 'adaptive'
settings.output = 'NEW_OBJECT'
