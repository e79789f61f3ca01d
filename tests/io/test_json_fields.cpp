// The JSON validation helper: every accessor's error names the file and the field path, says what
// was expected and shows what was found.
#include "io_test_util.hpp"

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/io/json_fields.hpp>

#include <gtest/gtest.h>

#include <fstream>

using namespace elastolearn;
using namespace elastolearn::io;
using nlohmann::json;
using test::expect_input_error;
using test::ScratchDir;

namespace {

const json k_scene = json::parse(R"({
  "format": "elastolearn-scene/1",
  "material": {"young": -3, "nu": "0.3", "density": 1000, "model": "stvk", "count": 2.5,
               "big": 1e12, "flag": 1, "name": 7, "gravity": [0, -9.8], "values": [1, "x", 3],
               "ids": [1, 2.0, 3.5], "whole": 3.0},
  "loads": [{"force": [0, 0, 1]}, 3],
  "dt": 0.01
})");

std::string message(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

} // namespace

TEST(JsonObject, ReadsValidFieldsAndFallbacks) {
  const JsonObject root(k_scene, "scene.json");
  const JsonObject material = root.object("material");
  EXPECT_EQ(material.path(), "material");
  EXPECT_EQ(material.number("density"), 1000.0);
  EXPECT_EQ(material.positive("density"), 1000.0);
  EXPECT_EQ(material.number("missing", 2.5), 2.5);
  EXPECT_EQ(material.positive("missing", 1.5), 1.5);
  EXPECT_EQ(material.integer("whole"), 3);
  EXPECT_EQ(material.integer("missing", -4), -4);
  EXPECT_TRUE(material.boolean("missing", true));
  EXPECT_EQ(material.string("model"), "stvk");
  EXPECT_EQ(material.string("missing", "x"), "x");
  EXPECT_EQ(material.choice("model", { "corotated", "stvk" }), "stvk");
  EXPECT_EQ(material.choice("missing", { "a", "b" }, "b"), "b");
  EXPECT_EQ(material.vec3("missing", Vec3(1, 2, 3)), Vec3(1, 2, 3));
  const json with_loads = json::parse(R"({"loads": [{"force": [0, 0, 1]}, {"force": [1, 0, 0]}]})");
  const std::vector<JsonObject> loads = JsonObject(with_loads, "scene.json").objects("loads");
  ASSERT_EQ(loads.size(), 2u);
  EXPECT_EQ(loads[1].vec3("force"), Vec3(1, 0, 0));
  EXPECT_EQ(loads[1].path(), "loads[1]");
  EXPECT_EQ(message([&] { loads[1].number("scale"); }),
      "scene.json: loads[1].scale: missing required field");
  EXPECT_EQ(root.number("dt"), 0.01);
  EXPECT_TRUE(root.has("loads"));
  EXPECT_FALSE(root.has("nothing"));
  EXPECT_EQ(root.field("dt"), "dt");
  EXPECT_EQ(material.field("young"), "material.young");
}

TEST(JsonObject, EveryAccessorErrorNamesFileAndPath) {
  const JsonObject root(k_scene, "scene.json");
  const JsonObject m = root.object("material");
  EXPECT_EQ(message([&] { m.positive("young"); }),
      "scene.json: material.young: expected a positive number, got -3");
  EXPECT_EQ(message([&] { m.positive("young", 1.0); }),
      "scene.json: material.young: expected a positive number, got -3");
  EXPECT_EQ(
      message([&] { m.number("nu"); }), "scene.json: material.nu: expected a number, got \"0.3\"");
  EXPECT_EQ(message([&] { m.number("nu", 0.0); }),
      "scene.json: material.nu: expected a number, got \"0.3\"");
  EXPECT_EQ(message([&] { m.number("poisson"); }),
      "scene.json: material.poisson: missing required field");
  EXPECT_EQ(message([&] { m.integer("count"); }),
      "scene.json: material.count: expected an integer, got 2.5");
  EXPECT_EQ(message([&] { m.integer("big", 0); }),
      "scene.json: material.big: expected an integer, got 1000000000000.0");
  EXPECT_EQ(message([&] { m.boolean("flag", false); }),
      "scene.json: material.flag: expected true or false, got 1");
  EXPECT_EQ(
      message([&] { m.string("name"); }), "scene.json: material.name: expected a string, got 7");
  EXPECT_EQ(message([&] { m.string("name", ""); }),
      "scene.json: material.name: expected a string, got 7");
  EXPECT_EQ(message([&] { m.vec3("gravity"); }),
      "scene.json: material.gravity: expected an array of 3 finite numbers, got [0,-9.8]");
  EXPECT_EQ(message([&] { m.numbers("values"); }),
      "scene.json: material.values[1]: expected a finite number, got \"x\"");
  EXPECT_EQ(message([&] { m.numbers("young"); }),
      "scene.json: material.young: expected an array of numbers, got -3");
  EXPECT_EQ(message([&] { m.integers("ids"); }),
      "scene.json: material.ids[2]: expected an integer, got 3.5");
  EXPECT_EQ(message([&] { m.object("model"); }),
      "scene.json: material.model: expected an object, got \"stvk\"");
  EXPECT_EQ(
      message([&] { root.objects("loads"); }), "scene.json: loads[1]: expected an object, got 3");
  EXPECT_EQ(message([&] { root.objects("dt"); }),
      "scene.json: dt: expected an array of objects, got 0.01");
  EXPECT_EQ(message([&] {
    m.choice("model", { "corotated", "neohookean" });
  }),
      "scene.json: material.model: expected one of \"corotated\", \"neohookean\", got \"stvk\"");
  EXPECT_EQ(message([&] { m.choice("density", { "a" }, "a"); }),
      "scene.json: material.density: expected one of \"a\", got 1000");
  EXPECT_EQ(message([&] { m.fail("", "inconsistent"); }), "scene.json: material: inconsistent");
  EXPECT_EQ(
      message([&] { JsonObject(json::array(), "m.json"); }), "m.json: expected an object, got []");
}

TEST(JsonObject, UnknownKeysAreRejectedWithASuggestion) {
  const json value = json::parse(R"({"yuong": 1, "nu": 0.3})");
  const JsonObject material(value, "mat.json", "material");
  EXPECT_EQ(message([&] {
    material.reject_unknown_keys({ "young", "nu", "density" });
  }),
      "mat.json: material.yuong: unknown field (did you mean \"young\"?)");
  const json other = json::parse(R"({"zzz": 1})");
  EXPECT_EQ(message([&] {
    JsonObject(other, "mat.json").reject_unknown_keys({ "young", "nu" });
  }),
      "mat.json: zzz: unknown field (expected one of \"young\", \"nu\")");
  EXPECT_NO_THROW(material.reject_unknown_keys({ "yuong", "nu" }));
}

TEST(JsonFile, SyntaxErrorsNameFileLineAndColumn) {
  ScratchDir dir;
  std::ofstream(dir / "bad.json") << "{\n  \"a\": 1,\n  \"b\": ]\n}\n";
  const std::string m = expect_input_error([&] { read_json_file(dir / "bad.json"); },
      { (dir / "bad.json").string() + ":3:", "invalid JSON" });
  EXPECT_NE(m.find(":3:8:"), std::string::npos) << m;
  expect_input_error([&] { read_json_file(dir / "none.json"); }, { "none.json" });
}

TEST(JsonFile, CheckFormatAcceptsKnownVersionsOnly) {
  auto check = [](const std::string& text) {
    const json value = json::parse(text);
    return check_format(JsonObject(value, "s.json"), "elastolearn-scene", 2);
  };
  EXPECT_EQ(check(R"({"format": "elastolearn-scene/1"})"), 1);
  EXPECT_EQ(check(R"({"format": "elastolearn-scene/2"})"), 2);
  EXPECT_EQ(message([&] { check(R"({"format": "elastolearn-scene/3"})"); }),
      "s.json: format: version 3 is newer than this elastolearn reads (up to "
      "\"elastolearn-scene/2\")");
  EXPECT_EQ(message([&] { check(R"({"format": "elastolearn-material/1"})"); }),
      "s.json: format: expected \"elastolearn-scene/2\", got \"elastolearn-material/1\" (not an "
      "elastolearn-scene file)");
  EXPECT_EQ(message([&] { check(R"({})"); }),
      "s.json: format: missing required field (expected \"elastolearn-scene/2\")");
  EXPECT_EQ(message([&] { check(R"({"format": "elastolearn-scene/x"})"); }),
      "s.json: format: invalid version in \"elastolearn-scene/x\"");
}

TEST(JsonFile, WriteIsAtomicPrettyAndRoundTrips) {
  ScratchDir dir;
  const json value
      = { { "format", "elastolearn-material/1" }, { "young", 1e5 }, { "list", { 1, 2, 3 } } };
  write_json_file(dir / "m.json", value);
  EXPECT_EQ(dir.files(), std::vector<std::string> { "m.json" });
  EXPECT_EQ(read_json_file(dir / "m.json"), value);
  const std::string text = read_text_file(dir / "m.json");
  EXPECT_NE(text.find("\n  \"format\""), std::string::npos); // 2-space indent
  EXPECT_EQ(text.back(), '\n');
}

TEST(ReadJsonFile, HostileTextIsOneInputErrorWithItsPlace) {
  ScratchDir dir;
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  // A number beyond double's range: nlohmann throws out_of_range, not parse_error.
  expect_input_error([&] { read_json_file(write("big.json", "{\n  \"young\": 1e999\n}")); },
      { "big.json:2:12", "number overflow parsing '1e999'" });
  // Deep nesting is refused before parsing (recursive code would exhaust the stack).
  expect_input_error([&] { read_json_file(write("deep.json", std::string(100000, '[') + "1")); },
      { "deep.json:1:257", "nested deeper than 256 levels" });
  // Brackets inside strings do not count.
  EXPECT_NO_THROW(read_json_file(write("str.json", "{\"a\": \"" + std::string(1000, '[') + "\"}")));
  expect_input_error([&] { read_json_file(dir.path()); }, { "is a folder, not a file" });
}
