// Scene files (parse and validate) and the scene of `snag check CLOTH --obstacle ...`.
#include "snag/scene/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "snag/error.h"
#include "snag/scene/scene_frames.h"

namespace snag::scene {
namespace {
namespace fs = std::filesystem;

using Pairs = std::vector<std::pair<int, int>>;
using Names = std::vector<std::string>;

/// The example of scene.h.
constexpr const char* kExample = R"({ "schema": "snag-scene/1",
  "objects": [
    {"name": "dress", "sequence": "dress.%04d.obj", "role": "cloth", "weld": 1e-6,
     "ignore": [["collar", "*"]]},
    {"name": "body", "sequence": "body.%04d.obj", "role": "obstacle"},
    {"name": "floor", "sequence": "floor.obj", "role": "obstacle", "against": ["dress"]}
  ] })";

/// The InputError that parsing `text` as "scene.json" throws; fails the test when none is thrown.
InputError parse_error(const std::string& text) {
  try {
    parse_scene(text, "scene.json");
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return InputError("", 0, "");
}

/// Expects parsing `text` to fail with a message that starts with the file name (and `line`, when
/// not 0) and holds each of `parts`.
void expect_error(const std::string& text, int64_t line, const std::vector<std::string>& parts) {
  const InputError e = parse_error(text);
  const std::string message = e.what();
  EXPECT_EQ(e.path(), "scene.json") << message;
  if (line > 0) {
    EXPECT_EQ(e.line(), line) << message;
    EXPECT_EQ(message.rfind("scene.json:" + std::to_string(line) + ": ", 0), 0u) << message;
  }
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "no '" << part << "' in: " << message;
  }
}

/// One object per line after "objects", so that objects[i] is on line i + 2.
std::string scene_of(const std::vector<std::string>& objects) {
  std::string text = "{\"objects\": [\n";
  for (size_t i = 0; i < objects.size(); ++i) {
    text += objects[i] + (i + 1 < objects.size() ? ",\n" : "\n");
  }
  return text + "]}\n";
}

const std::string kDress = R"({"name": "dress", "sequence": "dress.obj"})";
const std::string kBody = R"({"name": "body", "sequence": "body.obj", "role": "obstacle"})";

TEST(SceneParse, ExampleWithEveryKey) {
  const std::string text = R"({"schema": "snag-scene/1", "objects": [
    {"name": "dress", "sequence": "dress.%04d.obj", "role": "cloth", "group": "skirt",
     "self": false, "against": ["body"], "weld": 1e-6, "ignore": [["collar", "*"], ["a", "b"]]},
    {"name": "body", "sequence": "/abs/body.%04d.obj", "role": "obstacle", "self": true}
  ]})";
  const Scene scene = parse_scene(text, "scene.json");
  ASSERT_EQ(scene.objects.size(), 2u);
  ObjectSpec dress;
  dress.name = "dress";
  dress.sequence = "dress.%04d.obj";
  dress.role = Role::cloth;
  dress.group = "skirt";
  dress.self = false;
  dress.against = {"body"};
  dress.weld = 1e-6;
  dress.ignore = {{"collar", "*"}, {"a", "b"}};
  EXPECT_EQ(scene.objects[0], dress);
  ObjectSpec body;
  body.name = "body";
  body.sequence = "/abs/body.%04d.obj";
  body.role = Role::obstacle;
  body.self = true;
  EXPECT_EQ(scene.objects[1], body);
  EXPECT_EQ(scene.cross_checks(), (Pairs{{0, 1}}));
  EXPECT_EQ(scene.self_checks(), (std::vector<int>{1}));
}

TEST(SceneParse, ExampleOfTheHeader) {
  const Scene scene = parse_scene(kExample, "scene.json");
  ASSERT_EQ(scene.objects.size(), 3u);
  EXPECT_EQ(scene.objects[0].name, "dress");
  EXPECT_EQ(scene.objects[0].weld, 1e-6);
  EXPECT_EQ(scene.objects[0].ignore, (std::vector<IgnoreRule>{{"collar", "*"}}));
  EXPECT_EQ(scene.objects[0].against, (Names{"body", "floor"}));
  EXPECT_EQ(scene.objects[2].against, (Names{"dress"}));
  // dress-floor is listed by both and reported once; body and floor are not checked together.
  EXPECT_EQ(scene.cross_checks(), (Pairs{{0, 1}, {0, 2}}));
  EXPECT_EQ(scene.self_checks(), (std::vector<int>{0}));
}

TEST(SceneParse, Defaults) {
  const Scene scene = parse_scene(
      scene_of({kBody, kDress, R"({"name": "floor", "sequence": "floor.obj", "role": "obstacle"})",
                R"({"name": "shirt", "sequence": "shirt.obj"})"}),
      "scene.json");
  ASSERT_EQ(scene.objects.size(), 4u);
  const ObjectSpec& body = scene.objects[0];
  const ObjectSpec& dress = scene.objects[1];
  EXPECT_EQ(body.role, Role::obstacle);
  EXPECT_FALSE(body.self);
  EXPECT_TRUE(body.against.empty());
  EXPECT_EQ(dress.role, Role::cloth);  // no role: cloth
  EXPECT_TRUE(dress.self);
  EXPECT_EQ(dress.against, (Names{"body", "floor"}));  // every obstacle, not the other cloth
  EXPECT_FALSE(dress.group.has_value());
  EXPECT_FALSE(dress.weld.has_value());
  EXPECT_TRUE(dress.ignore.empty());
  EXPECT_EQ(scene.objects[3].against, (Names{"body", "floor"}));
  // Cloths against obstacles, never cloth against cloth or obstacle against obstacle.
  EXPECT_EQ(scene.cross_checks(), (Pairs{{0, 1}, {0, 3}, {1, 2}, {2, 3}}));
  EXPECT_EQ(scene.self_checks(), (std::vector<int>{1, 3}));
}

TEST(SceneParse, ExplicitSelfOnAnObstacleAndEmptyAgainstOnACloth) {
  const Scene scene = parse_scene(
      scene_of({R"({"name": "dress", "sequence": "dress.obj", "against": []})",
                R"({"name": "body", "sequence": "body.obj", "role": "obstacle", "self": true})"}),
      "scene.json");
  EXPECT_TRUE(scene.objects[1].self);
  EXPECT_TRUE(scene.objects[0].against.empty());
  EXPECT_TRUE(scene.cross_checks().empty());
  EXPECT_EQ(scene.self_checks(), (std::vector<int>{0, 1}));
}

TEST(SceneParse, ObstacleAgainstObstacleWhenAsked) {
  const Scene scene = parse_scene(
      scene_of(
          {kDress, kBody,
           R"({"name": "floor", "sequence": "f.obj", "role": "obstacle", "against": ["body"]})"}),
      "scene.json");
  EXPECT_EQ(scene.cross_checks(), (Pairs{{0, 1}, {0, 2}, {1, 2}}));
}

TEST(SceneParse, SchemaIsOptional) {
  EXPECT_EQ(parse_scene(scene_of({kDress}), "scene.json").objects.size(), 1u);
}

TEST(SceneParse, RelativeSequencesAreResolvedAgainstTheSceneDirectory) {
  const Scene scene = parse_scene(
      scene_of({R"({"name": "dress", "sequence": "frames/dress.%04d.obj"})",
                R"({"name": "body", "sequence": "/data/body.obj", "role": "obstacle"})"}),
      "/shots/s1/scene.json");
  EXPECT_EQ(fs::path(scene.objects[0].sequence), fs::path("/shots/s1/frames/dress.%04d.obj"));
  EXPECT_EQ(scene.objects[1].sequence, "/data/body.obj");
  // A scene file without a directory part: the sequence as written (relative to the working dir).
  EXPECT_EQ(parse_scene(scene_of({kDress}), "scene.json").objects[0].sequence, "dress.obj");
  EXPECT_EQ(fs::path(parse_scene(scene_of({kDress}), "../scene.json").objects[0].sequence),
            fs::path("../dress.obj"));
}

TEST(SceneErrors, RoleNotClothOrObstacle) {
  expect_error(scene_of({kDress, R"({"name": "b", "sequence": "b.obj", "role": "body"})"}), 3,
               {"objects[1].role: expected \"cloth\" or \"obstacle\", got \"body\""});
}

TEST(SceneErrors, MissingSequence) {
  expect_error(scene_of({R"({"name": "dress"})"}), 2, {"objects[0]: missing key \"sequence\""});
}

TEST(SceneErrors, MissingName) {
  expect_error(scene_of({kDress, R"({"sequence": "b.obj"})"}), 3,
               {"objects[1]: missing key \"name\""});
}

TEST(SceneErrors, EmptyNameOrSequence) {
  expect_error(scene_of({R"({"name": "", "sequence": "d.obj"})"}), 2,
               {"objects[0].name: expected a non-empty string, got \"\""});
  expect_error(scene_of({R"({"name": "d", "sequence": 3})"}), 2,
               {"objects[0].sequence: expected a non-empty string", "got 3"});
}

TEST(SceneErrors, AgainstNamesNoObject) {
  expect_error(scene_of({kBody, kDress,
                         R"({"name": "shirt", "sequence": "s.obj", "against": ["body", "bdy"]})"}),
               4, {"objects[2].against[1]: no object named \"bdy\""});
}

TEST(SceneErrors, AgainstItself) {
  expect_error(scene_of({kBody, R"({"name": "dress", "sequence": "d.obj", "against": ["dress"]})"}),
               3, {"objects[1].against[0]: an object is not checked against itself", "\"self\""});
}

TEST(SceneErrors, AgainstListsOneObjectTwice) {
  expect_error(
      scene_of({kBody, R"({"name": "dress", "sequence": "d.obj", "against": ["body", "body"]})"}),
      3, {"objects[1].against[1]: \"body\" is already listed at against[0]"});
}

TEST(SceneErrors, AgainstNotAnArrayOfNames) {
  expect_error(scene_of({kBody, R"({"name": "dress", "sequence": "d.obj", "against": "body"})"}), 3,
               {"objects[1].against: expected an array of object names, got \"body\""});
  expect_error(scene_of({kBody, R"({"name": "dress", "sequence": "d.obj", "against": [1]})"}), 3,
               {"objects[1].against[0]: expected an object name (a string), got 1"});
}

TEST(SceneErrors, DuplicateName) {
  expect_error(scene_of({R"({"name": "body", "sequence": "b.obj", "role": "obstacle"})", kDress,
                         R"({"name": "body", "sequence": "b2.obj", "role": "obstacle"})"}),
               4, {"objects[2].name: \"body\" is already the name of objects[0]"});
}

TEST(SceneErrors, NegativeOrNonNumericWeld) {
  expect_error(scene_of({R"({"name": "d", "sequence": "d.obj", "weld": -1e-6})"}), 2,
               {"objects[0].weld: expected a number >= 0", "got -1e-06"});
  expect_error(scene_of({R"({"name": "d", "sequence": "d.obj", "weld": "1e-6"})"}), 2,
               {"objects[0].weld: expected a number >= 0, got \"1e-6\""});
  // Beyond double range: nlohmann stops there (an out_of_range error, which has no position).
  expect_error(scene_of({R"({"name": "d", "sequence": "d.obj", "weld": 1e400})"}), 2,
               {"invalid JSON at column ", "number overflow parsing '1e400'"});
}

TEST(SceneErrors, UnknownKey) {
  const std::string text =
      "{\"objects\": [{\"name\": \"d\",\n \"sequence\": \"d.obj\",\n"
      " \"frobnicate\": 1}]}";
  expect_error(text, 3, {"objects[0].frobnicate: unknown key", "\"sequence\""});
  expect_error("{\"objects\": [" + kDress + "],\n \"object\": []}", 2,
               {"object: unknown key", "\"objects\""});
}

TEST(SceneErrors, DuplicateKey) {
  expect_error(
      "{\"objects\": [{\"name\": \"d\", \"sequence\": \"d.obj\",\n \"role\": \"cloth\",\n"
      " \"role\": \"obstacle\"}]}",
      3, {"objects[0].role: duplicate key (the first is on line 2)"});
}

TEST(SceneErrors, DuplicateKeyWrittenWithAnEscape) {
  expect_error(
      "{\"objects\": [{\"name\": \"d\", \"sequence\": \"d.obj\",\n \"na\\u006de\": \"e\"}]}", 2,
      {"objects[0].name: duplicate key (the first is on line 1)"});
}

TEST(SceneErrors, LinesCountedAfterAByteOrderMark) {
  expect_error(
      "\xEF\xBB\xBF" + scene_of({kDress, R"({"name": "b", "sequence": "b.obj", "role": 1})"}), 3,
      {"objects[1].role: expected \"cloth\" or \"obstacle\", got 1"});
}

TEST(SceneErrors, ObjectsNotANonEmptyArray) {
  expect_error(R"({"objects": []})", 1,
               {"objects: expected a non-empty array, got an empty array"});
  expect_error(R"({"objects": {"name": "d"}})", 1, {"objects: expected a non-empty array"});
  expect_error(R"({"schema": "snag-scene/1"})", 1, {"missing key \"objects\""});
  expect_error(scene_of({kDress, "\"body.obj\""}), 3,
               {"objects[1]: expected an object, got \"body.obj\""});
}

TEST(SceneErrors, TopLevelNotAnObject) {
  expect_error("[]", 1, {"expected an object {\"objects\": [...]} at the top level"});
}

TEST(SceneErrors, WrongSchema) {
  expect_error("{\"schema\": \"snag-scene/2\",\n \"objects\": [" + kDress + "], \"new\": 1}", 1,
               {"schema: expected \"snag-scene/1\", got \"snag-scene/2\""});
  expect_error("{\"schema\": 1, \"objects\": [" + kDress + "]}", 1,
               {"schema: expected \"snag-scene/1\", got 1"});
}

TEST(SceneErrors, IgnoreRulesThatAreNotPairsOfNames) {
  auto with_ignore = [](const std::string& ignore) {
    return scene_of({kBody, R"({"name": "d", "sequence": "d.obj", "ignore": )" + ignore + "}"});
  };
  expect_error(with_ignore(R"(["collar", "*"])"), 3,
               {"objects[1].ignore[0]: expected a pair of group names", "got \"collar\""});
  expect_error(with_ignore(R"([["collar"]])"), 3,
               {"objects[1].ignore[0]: expected a pair of group names", "got an array"});
  expect_error(with_ignore(R"([["a", "b", "c"]])"), 3, {"objects[1].ignore[0]: expected a pair"});
  expect_error(with_ignore(R"([["a", "b"], ["collar", 2]])"), 3,
               {"objects[1].ignore[1][1]: expected a group name", "got 2"});
  expect_error(with_ignore(R"([["", "b"]])"), 3,
               {"objects[1].ignore[0][0]: expected a group name", "got \"\""});
  expect_error(with_ignore(R"({"a": "b"})"), 3,
               {"objects[1].ignore: expected an array of group-name pairs", "got an object"});
}

TEST(SceneErrors, OtherTypeMistakes) {
  expect_error(scene_of({R"({"name": "d", "sequence": "d.obj", "self": "yes"})"}), 2,
               {"objects[0].self: expected true or false, got \"yes\""});
  expect_error(scene_of({R"({"name": "d", "sequence": "d.obj", "group": ""})"}), 2,
               {"objects[0].group: expected a group name", "got \"\""});
}

TEST(SceneErrors, NoCloth) {
  expect_error(scene_of({kBody}), 1, {"objects: no object has role \"cloth\""});
}

TEST(SceneErrors, JsonSyntaxErrorHasItsLine) {
  const InputError e = parse_error("{\"objects\": [\n  {\"name\": \"d\",\n   \"sequence\": }\n]}");
  EXPECT_EQ(e.line(), 3) << e.what();
  EXPECT_NE(std::string(e.what()).find("scene.json:3: invalid JSON at column 16: syntax error"),
            std::string::npos)
      << e.what();
  EXPECT_EQ(std::string(e.what()).find("json.exception"), std::string::npos) << e.what();
  const InputError end = parse_error("{\"objects\": [\n");
  EXPECT_EQ(end.line(), 2) << end.what();
  EXPECT_EQ(parse_error("").line(), 1);
}

TEST(SceneErrors, LongValuesAreShortenedInMessages) {
  const std::string role(500, 'x');
  const InputError e =
      parse_error(scene_of({R"({"name": "d", "sequence": "d.obj", "role": ")" + role + "\"}"}));
  EXPECT_LT(std::string(e.what()).size(), 200u) << e.what();
}

TEST(SceneErrors, DeepNestingIsRejectedWithoutExhaustingTheStack) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  expect_error(scene_of({R"({"name": "d", "sequence": "d.obj", "ignore": )" + deep + "}"}), 2,
               {"objects[0].ignore[0]: expected a pair"});
}

TEST(SceneErrors, CrossChecksOfAHandBuiltSceneWithAnUnknownName) {
  Scene scene = scene_from_flags("cloth.obj", {}, std::nullopt);
  scene.objects[0].against = {"body"};
  EXPECT_THROW(scene.cross_checks(), InternalError);
  scene.objects[0].against = {"cloth"};
  EXPECT_THROW(scene.cross_checks(), InternalError);
}

/// A fresh directory for one test, removed afterwards.
class SceneFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("snag_scene_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }

  /// A cloth "dress" of three frames, dress.0001.obj to dress.0003.obj (one triangle each, at
  /// offsets 1 to 3), checked against `against`.
  ObjectSpec dress_of_three_frames(std::vector<std::string> against) const;

  fs::path dir_;
};

TEST_F(SceneFile, ReadsTheExampleAndResolvesRelativeSequences) {
  const Scene scene = read_scene_file(write("scene.json", kExample));
  ASSERT_EQ(scene.objects.size(), 3u);
  EXPECT_EQ(fs::path(scene.objects[0].sequence), dir_ / "dress.%04d.obj");
  EXPECT_EQ(fs::path(scene.objects[2].sequence), dir_ / "floor.obj");
  EXPECT_EQ(scene.cross_checks(), (Pairs{{0, 1}, {0, 2}}));
}

TEST_F(SceneFile, ErrorsNameTheFileAndLine) {
  const std::string path = write("bad.json", scene_of({kDress, R"({"name": "b", "sequence": "b.obj",
  "role": "body"})"}));
  try {
    read_scene_file(path);
    FAIL() << "accepted a role \"body\"";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(std::string(e.what()),
              path + ":4: objects[1].role: expected \"cloth\" or \"obstacle\", got \"body\"");
  }
}

TEST_F(SceneFile, MissingFileOrDirectory) {
  EXPECT_THROW(read_scene_file((dir_ / "none.json").string()), InputError);
  EXPECT_THROW(read_scene_file(dir_.string()), InputError);
}

TEST(SceneFromFlags, ClothAndObstaclesNamedAfterTheirFiles) {
  const Scene scene =
      scene_from_flags("shot/dress.%04d.obj", {"shot/body.%04d.obj", "floor.obj"}, 1e-5);
  ASSERT_EQ(scene.objects.size(), 3u);
  EXPECT_EQ(scene.objects[0].name, "cloth");
  EXPECT_EQ(scene.objects[0].role, Role::cloth);
  EXPECT_EQ(scene.objects[0].sequence, "shot/dress.%04d.obj");
  EXPECT_TRUE(scene.objects[0].self);
  EXPECT_EQ(scene.objects[0].against, (Names{"body", "floor"}));
  EXPECT_EQ(scene.objects[1].name, "body");
  EXPECT_EQ(scene.objects[1].sequence, "shot/body.%04d.obj");  // kept as given
  EXPECT_EQ(scene.objects[1].role, Role::obstacle);
  EXPECT_FALSE(scene.objects[1].self);
  EXPECT_TRUE(scene.objects[1].against.empty());
  EXPECT_EQ(scene.objects[2].name, "floor");
  for (const ObjectSpec& o : scene.objects) EXPECT_EQ(o.weld, 1e-5);
  EXPECT_EQ(scene.cross_checks(), (Pairs{{0, 1}, {0, 2}}));
  EXPECT_EQ(scene.self_checks(), (std::vector<int>{0}));
}

TEST(SceneFromFlags, NoObstacles) {
  const Scene scene = scene_from_flags("dress.obj", {}, std::nullopt);
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_TRUE(scene.cross_checks().empty());
  EXPECT_EQ(scene.self_checks(), (std::vector<int>{0}));
  EXPECT_FALSE(scene.objects[0].weld.has_value());
}

TEST(SceneFromFlags, NamesLeaveOutFrameTokensGlobsAndFrameDigits) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"body.%04d.obj", "body"},   {"body.%d.obj", "body"},       {"body.####.obj", "body"},
      {"body.@@@@.ply", "body"},   {"body.$F4.obj", "body"},      {"body_*.ply", "body"},
      {"body.[0-9]*.obj", "body"}, {"body.0001.obj", "body"},     {"body0001.obj", "body"},
      {"body-12.obj", "body"},     {"body_v2.obj", "body_v2"},    {"t0.ply", "t0"},
      {"sim/body/", "body"},       {"sim/body/%04d.obj", "body"}, {"sim/body/0001.obj", "body"},
      {"%04d.obj", "obstacle"},    {"arm.left.obj", "arm.left"},
  };
  for (const auto& [sequence, name] : cases) {
    EXPECT_EQ(scene_from_flags("c.obj", {sequence}, std::nullopt).objects[1].name, name)
        << sequence;
  }
}

TEST(SceneFromFlags, CollidingNamesGetSuffixes) {
  const Scene scene = scene_from_flags(
      "dress.obj",
      {"a/body.%04d.obj", "b/body.%04d.obj", "cloth.obj", "body-2.obj", "c/body.obj", "cloth.ply"},
      std::nullopt);
  Names names;
  for (const ObjectSpec& o : scene.objects) names.push_back(o.name);
  // body-2.obj is a "body" (frame digits after a separator) and takes the next free suffix.
  EXPECT_EQ(names, (Names{"cloth", "body", "body-2", "cloth-2", "body-3", "body-4", "cloth-3"}));
  EXPECT_EQ(scene.objects[0].against,
            (Names{"body", "body-2", "cloth-2", "body-3", "body-4", "cloth-3"}));
  EXPECT_EQ(scene.cross_checks().size(), 6u);
}

// ---------------------------------------------------------------------------------------------
// Found by mutation testing: each of these passed with a wrong change to scene.cpp or
// scene_frames.cpp before.

TEST(SceneFromFlags, ThreeOrMoreTrailingDigitsAreAFrameNumberFewerAreKept) {
  // scene_from_flags: "digits after a separator, or 3 or more" are frame digits.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"body001.obj", "body"},  {"body123.ply", "body"}, {"scan007.%04d.obj", "scan"},
      {"body12.obj", "body12"}, {"v2.obj", "v2"},
  };
  for (const auto& [sequence, name] : cases) {
    EXPECT_EQ(scene_from_flags("c.obj", {sequence}, std::nullopt).objects[1].name, name)
        << sequence;
  }
}

/// One triangle a little off the origin, as an OBJ.
std::string one_triangle_obj(double offset) {
  const std::string o = std::to_string(offset);
  return "v " + o + " 0 0\nv 1 " + o + " 0\nv 0 1 " + o + "\nf 1 2 3\n";
}

ObjectSpec SceneFile::dress_of_three_frames(std::vector<std::string> against) const {
  for (int f = 1; f <= 3; ++f) write("dress.000" + std::to_string(f) + ".obj", one_triangle_obj(f));
  ObjectSpec dress;
  dress.name = "dress";
  dress.sequence = (dir_ / "dress.%04d.obj").string();
  dress.against = std::move(against);
  return dress;
}

std::vector<int64_t> numbers_of(const std::vector<seq::Frame>& frames) {
  std::vector<int64_t> numbers;
  for (const seq::Frame& f : frames) numbers.push_back(f.number);
  return numbers;
}

TEST_F(SceneFile, TheFirstClothSetsTheFramesEvenWhenAnObstacleIsListedFirst) {
  const ObjectSpec cloth = dress_of_three_frames({"body"});
  Scene scene;
  ObjectSpec obstacle;
  obstacle.name = "body";
  obstacle.sequence = write("body.obj", one_triangle_obj(5));
  obstacle.role = Role::obstacle;
  obstacle.self = false;
  scene.objects = {obstacle, cloth};
  const ResolvedScene resolved = resolve_scene(scene, "");
  EXPECT_EQ(numbers_of(resolved.frames), (std::vector<int64_t>{1, 2, 3}));
  ASSERT_EQ(resolved.objects.size(), 2u);
  EXPECT_TRUE(resolved.objects[0].still);
  EXPECT_FALSE(resolved.objects[1].still);
  EXPECT_EQ(resolved.objects[1].frames, resolved.frames);
  EXPECT_EQ(resolved.objects[1].frames[2].path, dir_ / "dress.0003.obj");
  EXPECT_EQ(resolved.checks, (std::vector<detect::PartCheck>{{0, 1}, {1, 1}}));
  const ResolvedScene selected = resolve_scene(scene, "2-3");
  EXPECT_EQ(numbers_of(selected.frames), (std::vector<int64_t>{2, 3}));
}

TEST_F(SceneFile, ASecondClothOfOneFileIsStill) {
  // "an object with a single file that is not one of several frames is still", whatever its
  // role: a second cloth of one file is read once and checked in every frame.
  const ObjectSpec dress = dress_of_three_frames({"patch"});
  const std::string patch = write("patch.obj", one_triangle_obj(7));
  Scene scene;
  ObjectSpec second;
  second.name = "patch";
  second.sequence = patch;
  scene.objects = {dress, second};
  const ResolvedScene resolved = resolve_scene(scene, "");
  EXPECT_EQ(numbers_of(resolved.frames), (std::vector<int64_t>{1, 2, 3}));
  ASSERT_EQ(resolved.objects.size(), 2u);
  EXPECT_TRUE(resolved.objects[1].still);
  const SceneReader reader(resolved);
  std::vector<io::FrameReader> readers = reader.make_readers();
  for (size_t i = 0; i < 3; ++i) {
    const SceneFrame frame = reader.read(i, readers);
    ASSERT_EQ(frame.mesh.triangles.size(), 2u);
    EXPECT_EQ(frame.files[1], patch);
    EXPECT_EQ(frame.mesh.positions[3].x, 7.0);  // the patch's first vertex, after the dress's 3
  }
}

TEST_F(SceneFile, ASceneOfOneGroupObjectReadsOnlyThatGroup) {
  // shirt.obj: sleeve (triangles 0 and 2) and collar (triangle 1, vertices 1, 2, 3 of the
  // file); a scene of the collar alone has its one triangle and three vertices.
  const std::string shirt = write("shirt.obj",
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n"
                                  "g sleeve\nf 1 2 4\ng collar\nf 1 2 3\ng sleeve\nf 2 3 5\n");
  Scene scene;
  ObjectSpec collar;
  collar.name = "collar";
  collar.sequence = shirt;
  collar.group = "collar";
  scene.objects = {collar};
  const ResolvedScene resolved = resolve_scene(scene, "");
  const SceneReader reader(resolved);
  std::vector<io::FrameReader> readers = reader.make_readers();
  const SceneFrame frame = reader.read(0, readers);
  ASSERT_EQ(frame.mesh.triangles.size(), 1u);
  EXPECT_EQ(frame.mesh.positions.size(), 3u);
  EXPECT_EQ(frame.file_triangle, (std::vector<int32_t>{1}));
  EXPECT_EQ(frame.file_vertex, (std::vector<int32_t>{0, 1, 2}));
  EXPECT_EQ(frame.layout.triangle_begin, (std::vector<int32_t>{0, 1}));
  EXPECT_EQ(frame.layout.vertex_begin, (std::vector<int32_t>{0, 3}));
}

}  // namespace
}  // namespace snag::scene
