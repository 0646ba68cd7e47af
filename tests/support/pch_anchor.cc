// The precompiled header of every test (tests/CMakeLists.txt,
// vmh_test_pch) is built with this empty source; the tests reuse it.
