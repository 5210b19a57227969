// The translation unit that tofguard_test_pch's precompiled header is built
// with (tests/CMakeLists.txt); the test executables reuse the header, none
// links this.
