# The numerical studies (`vmhaptics study`, docs/numerics.md) and what they
# draw with. Included from tests/CMakeLists.txt, so the source paths are
# relative to tests/.

# sim/svg_chart.cc: x-y charts, checked by reading the pixels back
vmh_add_test(svg_chart_test sim/svg_chart_test.cc)
target_link_libraries(svg_chart_test PRIVATE vmhaptics::sim)
target_include_directories(svg_chart_test PRIVATE ${PROJECT_SOURCE_DIR})

# sim/stability_study.cc: K_crit of the sampled-data wall by simulation
# against Gil et al.'s bound and the exact discrete loop
vmh_add_test(stability_study_test sim/stability_study_test.cc)
target_link_libraries(stability_study_test PRIVATE vmhaptics::sim)
target_include_directories(stability_study_test PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_definitions(stability_study_test PRIVATE
                           VMH_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")

# `vmhaptics study ...` as a user runs it (tests/cli/): JSON, files, errors
if(VMH_BUILD_CLI)
  vmh_add_test(study_stability_test cli/study_stability_test.cc)
  target_link_libraries(study_stability_test PRIVATE
                        nlohmann_json::nlohmann_json)
  target_include_directories(study_stability_test PRIVATE
                             ${PROJECT_SOURCE_DIR})
  target_compile_definitions(study_stability_test PRIVATE
                             VMH_CLI_PATH="$<TARGET_FILE:vmhaptics>"
                             VMH_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")
  add_dependencies(study_stability_test vmhaptics)
endif()
