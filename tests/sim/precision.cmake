# sim/precision_study.cc and sim/leanness_study.cc (issue 5, items 1 and 4),
# and their sub-verbs `vmhaptics study precision` and `study leanness`.
# Included from tests/CMakeLists.txt, so the source paths are relative to
# tests/.
foreach(t precision_study_test leanness_study_test)
  vmh_add_test(${t} sim/${t}.cc)
  target_link_libraries(${t} PRIVATE vmhaptics::sim)
  target_include_directories(${t} PRIVATE ${PROJECT_SOURCE_DIR})
  target_compile_definitions(${t} PRIVATE
    VMH_MODELS_DIR="${PROJECT_SOURCE_DIR}/models"
    VMH_TEST_SCENES_DIR="${CMAKE_CURRENT_SOURCE_DIR}/sim/scenes")
endforeach()

if(VMH_BUILD_CLI)
  vmh_add_test(study_precision_cli_test cli/study_precision_cli_test.cc)
  target_link_libraries(study_precision_cli_test PRIVATE
                        nlohmann_json::nlohmann_json)
  target_include_directories(study_precision_cli_test PRIVATE
                             ${PROJECT_SOURCE_DIR})
  target_compile_definitions(study_precision_cli_test PRIVATE
                             VMH_CLI_PATH="$<TARGET_FILE:vmhaptics>"
                             VMH_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")
  add_dependencies(study_precision_cli_test vmhaptics)
endif()
