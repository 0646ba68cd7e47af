# sim/extremes_study.cc and sim/fault_injector.cc: the stiff and extreme
# cases (issue 5, item 3), the sensor-fault injector and guard, the servo
# jitter and the passivity observer. Included from tests/CMakeLists.txt, so
# source paths are relative to tests/.
vmh_add_test(extremes_study_test sim/extremes_study_test.cc)
target_link_libraries(extremes_study_test PRIVATE vmhaptics::sim)
target_include_directories(extremes_study_test PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_definitions(extremes_study_test PRIVATE
                           VMH_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")

# no MuJoCo here: the decorators against a scripted device, and the
# allocation counter (support/alloc_counter.cc replaces operator new)
vmh_add_test(fault_injector_test sim/fault_injector_test.cc
             support/alloc_counter.cc)
target_link_libraries(fault_injector_test PRIVATE vmhaptics::sim)
target_include_directories(fault_injector_test PRIVATE ${PROJECT_SOURCE_DIR})

if(VMH_BUILD_CLI)
  # `vmhaptics study extremes` as a user runs it
  vmh_add_test(study_extremes_test cli/study_extremes_test.cc)
  target_link_libraries(study_extremes_test PRIVATE nlohmann_json::nlohmann_json)
  target_include_directories(study_extremes_test PRIVATE ${PROJECT_SOURCE_DIR})
  target_compile_definitions(study_extremes_test PRIVATE
                             VMH_CLI_PATH="$<TARGET_FILE:vmhaptics>")
  add_dependencies(study_extremes_test vmhaptics)
endif()
