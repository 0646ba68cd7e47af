# hw run --device openhaptics case1 through build/lib/libHD.so (the
# project's own HD library, over the emulator playing case 1): it must end
# with exit 0, its claims judged on the plant's truth and all of them met.
file(REMOVE_RECURSE ${OUT})
execute_process(
  COMMAND ${VMH} hw run --device openhaptics case1 --out ${OUT}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "hw run exited ${rc}: ${err}")
endif()
foreach(expect "\"claims_judged\": true" "\"all_claims_pass\": true"
               "\"claims_measured_on\": \"the emulator's ground truth\"")
  string(FIND "${out}" "${expect}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "hw run's summary lacks ${expect}")
  endif()
endforeach()
