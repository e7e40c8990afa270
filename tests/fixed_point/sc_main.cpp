// gtest_main provides main(); libsystemc still needs the user's sc_main symbol to link.
extern "C" int sc_main(int, char**) { return 0; }
