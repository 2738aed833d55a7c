"""Results kept live: prepared meshes cached per mesh state, change tracking, the modal live
preview's session and Regenerate."""
