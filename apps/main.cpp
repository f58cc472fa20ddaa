// bbm: the program's entry point. The command line is apps/cli.cpp.
int bbm_cli_main(int argc, char** argv);

int main(int argc, char** argv) { return bbm_cli_main(argc, argv); }
