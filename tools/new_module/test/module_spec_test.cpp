#include "module_spec.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::new_module {
namespace {
using testing::HasSubstr;
using testing::ThrowsMessage;

ModuleSpec valid() {
  ModuleSpec s;
  s.name = "line_fuser";
  s.inputs = {{"left", "LineSeg3DSeq"}, {"trigger", "Bool"}};
  s.outputs = {{"fused", "LineSeg3DSeq"}};
  s.params = {{"gain", "double", "1.5"}, {"period", "duration", "33ms"}};
  return s;
}

void expect_error(const ModuleSpec& s, const std::string& message) {
  EXPECT_THAT(
      [&] {
        s.validate({"relay", "logger"});
      },
      ThrowsMessage<std::invalid_argument>(HasSubstr(message)));
}

TEST(ModuleSpec, AcceptsAValidModuleAndNamesItsClass) {
  EXPECT_NO_THROW(valid().validate({"relay"}));
  EXPECT_EQ(valid().class_name(), "LineFuser");
}

TEST(ModuleSpec, ParsesPortsAndParams) {
  const auto p = ModuleSpec::parse_port("img:oscar::GvImage", "--input");
  EXPECT_EQ(p.name, "img");
  EXPECT_EQ(p.type, "GvImage");
  const auto q = ModuleSpec::parse_param("label:string=a b");
  EXPECT_EQ(q.default_value, "a b");
  EXPECT_THAT([] { ModuleSpec::parse_port("img", "--input"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("--input 'img': expected name:Type, e.g. image:GvImage")));
  EXPECT_THAT([] { ModuleSpec::parse_param("gain:double"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("--param 'gain:double': expected name:type=default")));
}

TEST(ModuleSpec, RejectsBadNamesClashesTypesAndDefaults) {
  auto s = valid();
  s.name = "2fast";
  expect_error(s, "module name '2fast' is not a C++ identifier");
  s.name = "LineFuser";
  expect_error(s, "module name 'LineFuser' must be snake_case");
  s.name = "relay";
  expect_error(s,
               "module name 'relay' is taken: a kernel type or module folder of that name exists");
  s = valid();
  s.inputs[0].name = "class";
  expect_error(s, "input 'class' is a C++ keyword");
  s = valid();
  s.inputs[1].name = "left";
  expect_error(s, "input 'left': the name is used twice");
  s = valid();
  s.outputs[0].type = "Image";
  expect_error(s,
               "output 'fused': unknown cue type 'Image' (known: Bool, LineSeg3DSeq, GvImage; a "
               "type of the module's own needs --type Image)");
  s = valid();
  s.params[0].type = "float";
  expect_error(
      s, "param 'gain': unknown type 'float' (known: bool, int, int64, double, string, duration)");
  s = valid();
  s.params[1].default_value = "soon";
  expect_error(s, "param 'period': default 'soon' is no duration value (e.g. 33ms, 1.5s)");
  s = valid();
  s.outputs.clear();
  expect_error(s, "a module needs at least one --output name:Type");
}

TEST(ModuleSpec, RejectsTypesOfItsOwnThatAreNoCamelCaseNamesOrOscarsOrForInputs) {
  auto s = valid();
  s.types = {"fusedLines"};
  expect_error(s, "--type 'fusedLines' must be CamelCase (a capital, then letters and digits)");
  s.types = {"Bool"};
  expect_error(s, "--type 'Bool' is OSCAR's own cue type: use it without --type");
  s.types = {"Struct"};
  expect_error(s, "--type 'Struct' is an IDL keyword");
  s.types = {"Fused", "Fused"};
  expect_error(s, "--type 'Fused' is given twice");
  s.types = {"Fused"};
  s.inputs[0].type = "Fused";
  expect_error(s, "input 'left': a --type of the module's own is for its outputs");
  s = valid();
  s.name = "sequence";
  s.types = {"Fused"};
  expect_error(s, "module name 'sequence' is an IDL keyword");
  s.name = "oscar";
  expect_error(s, "module name 'oscar' is OSCAR's IDL module");
  s = valid();
  s.outputs[0].type = "Fused";
  expect_error(s,
               "unknown cue type 'Fused' (known: Bool, LineSeg3DSeq, GvImage; a type of the "
               "module's own needs --type Fused)");
  s.types = {"Fused"};
  EXPECT_NO_THROW(s.validate({}));
}

TEST(ModuleSpec, GeneratesTheIdlOfItsOwnTypesAndUsesThem) {
  auto s = valid();
  s.outputs.push_back({"quality", "FuseQuality"});
  s.types = {"FuseQuality"};
  const auto files = generate(s);
  ASSERT_EQ(files.size(), 9u);
  const auto& idl = files.at("line_fuser_types.idl");
  EXPECT_THAT(idl, HasSubstr("#include \"oscar/cue_header.idl\"\nmodule line_fuser {\n"
                             "  struct FuseQuality {\n    oscar::CueHeader header;"));
  EXPECT_THAT(files.at("line_fuser_types.hpp"),
              HasSubstr("#include <line_fuser/line_fuser_types.h>\n"
                        "#include <line_fuser/line_fuser_typesPubSubTypes.h>"));
  EXPECT_THAT(files.at("line_fuser_types.hpp"),
              HasSubstr("OSCAR_DECLARE_CUE_TYPE(line_fuser, FuseQuality)"));
  EXPECT_THAT(files.at("CMakeLists.txt"), HasSubstr("\n  IDL line_fuser_types.idl)\n"));
  EXPECT_THAT(files.at("CMakeLists.txt"), HasSubstr("\n  LIBS oscar_kernel_line_fuser_objects)"));
  EXPECT_THAT(files.at("line_fuser_kernel.hpp"), HasSubstr("#include \"line_fuser_types.hpp\""));
  EXPECT_THAT(files.at("line_fuser_kernel.hpp"),
              HasSubstr("  oscar::Output<line_fuser::FuseQuality>& quality_;"));
  EXPECT_THAT(files.at("line_fuser_kernel.cpp"),
              HasSubstr("setup.output<line_fuser::FuseQuality>(\"quality\")"));
  EXPECT_THAT(files.at("test/line_fuser_kernel_test.cpp"), HasSubstr("oscar::find_idl_text(type)"));
  const auto& system_test = files.at("test/line_fuser_system_test.cpp");
  EXPECT_THAT(system_test, HasSubstr("wait_for_cues({\"line_fuser/fused\"})"))
      << "only OSCAR's types";
  EXPECT_THAT(system_test,
              HasSubstr("read_cues<line_fuser::FuseQuality>(\"line_fuser/quality\", 3)"));
  EXPECT_THAT(files.at("README.md"), HasSubstr("| `quality` | out | `line_fuser::FuseQuality` |"));
}

TEST(ModuleSpec, GeneratesTheFolderOfAModule) {
  auto s = valid();
  const auto files = generate(s);
  ASSERT_EQ(files.size(), 7u);
  EXPECT_EQ(files.at("CMakeLists.txt"),
            "oscar_add_module(NAME line_fuser SOURCES line_fuser_kernel.cpp TEST "
            "test/line_fuser_kernel_test.cpp)\n"
            "oscar_add_system_test(NAME oscar_kernel_line_fuser_system_test SOURCES "
            "test/line_fuser_system_test.cpp\n"
            "  SYSTEM test/line_fuser_system.yaml LABELS integration DEPENDS "
            "oscar_kernel_line_fuser oscar_kernel_bench_source)\n");
  // The system test boots a small system: a bench_source per input feeds the kernel.
  const auto& yaml = files.at("test/line_fuser_system.yaml");
  EXPECT_THAT(yaml, HasSubstr("  - name: trigger_source\n"
                              "    kernels: [ { type: bench_source, name: trigger_source, "
                              "params: { type: Bool } } ]\n"));
  EXPECT_THAT(yaml, HasSubstr("params: { type: LineSeg3DSeq, lines: 10 }"));
  EXPECT_THAT(yaml, HasSubstr("    kernels: [ { type: line_fuser, name: line_fuser, inputs: { "
                              "left: left_source/out, trigger: trigger_source/out"));
  const auto& system_test = files.at("test/line_fuser_system_test.cpp");
  EXPECT_THAT(system_test, HasSubstr("using LineFuserSystem = oscar::testing::BootedSystem;"));
  EXPECT_THAT(system_test, HasSubstr("read_cues<oscar::LineSeg3DSeq>(\"line_fuser/fused\", 3)"));
  EXPECT_THAT(system_test, HasSubstr("configure(\"line_fuser\", oscar::CMD_SET_CYCLE"));
  const auto& hpp = files.at("line_fuser_kernel.hpp");
  EXPECT_THAT(hpp, HasSubstr("class LineFuser final : public oscar::Kernel"));
  EXPECT_THAT(hpp, HasSubstr("    double gain = 1.5;\n"));
  EXPECT_THAT(
      hpp, HasSubstr("    std::chrono::nanoseconds period = std::chrono::nanoseconds{33000000};"));
  EXPECT_THAT(hpp, HasSubstr("  oscar::Input<oscar::Bool>& trigger_;"));
  EXPECT_THAT(hpp, HasSubstr("  oscar::Output<oscar::LineSeg3DSeq>& fused_;"));
  EXPECT_THAT(files.at("line_fuser_kernel.cpp"),
              HasSubstr("OSCAR_REGISTER_KERNEL(oscar::modules::LineFuser, \"line_fuser\")"));
  EXPECT_THAT(files.at("README.md"), HasSubstr("| `left` | in | `oscar::LineSeg3DSeq` |"));
  EXPECT_THAT(files.at("README.md"), HasSubstr("| `period` | duration | `33ms` |"));
  s.out_of_tree = true;
  EXPECT_THAT(generate(s).at("CMakeLists.txt"), HasSubstr("find_package(oscar REQUIRED)"));
  EXPECT_THAT(generate(s).at("CMakeLists.txt"),
              HasSubstr("SYSTEM test/line_fuser_system.yaml DEPENDS oscar_kernel_line_fuser)"));
  EXPECT_THAT(generate(s).at("line_fuser_kernel.cpp"), HasSubstr("namespace line_fuser_module {"));
}

}  // namespace
}  // namespace oscar::new_module
