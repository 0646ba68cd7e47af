// an empty source: a test's target (tests/CMakeLists.txt, vmh_add_test) holds its settings and compiles only this
