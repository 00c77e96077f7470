# The coarse dry scene of the main job and the dataset benchmark (sourced): 32 x 6 quadratic
# elements and 32-point surface fits, a few seconds per tool draw; the protocol is the default
# press-slide one (four tools, 2 um run-in, 2.5 um window). Extra `--set` overrides may follow it.
coarse_scene=(--set geometry.chip_surface.fit.control_points=32 --set geometry.tool_surface.fit.control_points=32
              --set discretisation.elements_x=32 --set discretisation.elements_y=6)
