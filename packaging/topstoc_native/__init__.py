"""TopStoc's compiled engine `_topstoc` on its own, for the Blender extension (whose add-on
package holds no binary). Everything else is in the `topstoc` package."""
