# sim/plot_svg.cc: the thesis's views and time histories as SVG, drawn from
# real closed-loop runs of cases 2 (circle) and 5 (sphere). Included from
# tests/CMakeLists.txt, so the source path is relative to tests/.
vmh_add_test(plot_svg_test sim/plot_svg_test.cc)
target_link_libraries(plot_svg_test PRIVATE vmhaptics::sim)
target_include_directories(plot_svg_test PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_definitions(plot_svg_test PRIVATE
                           VMH_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")
