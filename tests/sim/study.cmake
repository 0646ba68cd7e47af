# The numerical studies (`vmhaptics study`, docs/numerics.md) and what they
# draw with. Included from tests/CMakeLists.txt, so the source paths are
# relative to tests/.

# sim/svg_chart.cc: x-y charts, checked by reading the pixels back
vmh_add_test(svg_chart_test sim/svg_chart_test.cc)
target_link_libraries(svg_chart_test PRIVATE vmhaptics::sim)
target_include_directories(svg_chart_test PRIVATE ${PROJECT_SOURCE_DIR})
