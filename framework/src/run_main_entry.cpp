// The entry point of oscar-run and of every module's stand-alone runner.
namespace oscar {
int run_main(int argc, char** argv);
}
int main(int argc, char** argv) { return oscar::run_main(argc, argv); }
