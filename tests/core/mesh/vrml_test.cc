// WriteVrml: the file is read back by a small VRML97 tokenizer written here (ISO/IEC 14772-1
// 5.1: '#' comments, ',' is white space, braces and brackets delimit nodes and multi-valued
// fields), which checks the structure (balanced braces, the header, the node and field names the
// header of vrml_io.h promises) and that the values are exactly the mesh's.
#include <gtest/gtest.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/mesh/vrml_io.h"
#include "tests/core/mesh/mesh_test_util.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

std::vector<std::string> Tokenize(const std::string& text) {
  std::vector<std::string> tokens;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '#') {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ',') {
      ++i;
    } else if (c == '{' || c == '}' || c == '[' || c == ']') {
      tokens.emplace_back(1, c);
      ++i;
    } else {
      size_t end = i;
      while (end < text.size() && std::string(" \t\r\n,{}[]#").find(text[end]) == std::string::npos) ++end;
      tokens.push_back(text.substr(i, end - i));
      i = end;
    }
  }
  return tokens;
}

// A parsed VRML file: the path of node and field names to each multi-valued field ("Shape
// geometry IndexedFaceSet coord Coordinate point") with its values, and the single-valued fields.
struct VrmlFile {
  std::map<std::string, std::vector<std::string>> multi_fields;
  std::map<std::string, std::string> single_fields;  // path -> value(s) joined by ' '
};

// Node := TypeName '{' { field value } '}'; value := Node | '[' tokens ']' | tokens up to the next
// field name (an identifier starting with a lower-case letter). Fails on unbalanced braces.
class VrmlReader {
 public:
  explicit VrmlReader(std::vector<std::string> tokens) : tokens_(std::move(tokens)) {}

  bool Read(VrmlFile* file) {
    file_ = file;
    while (position_ < tokens_.size()) {
      if (!ReadNode("")) return false;
    }
    return true;
  }

 private:
  static bool IsFieldName(const std::string& token) { return !token.empty() && std::islower(token[0]); }
  static bool IsTypeName(const std::string& token) { return !token.empty() && std::isupper(token[0]); }

  bool ReadNode(const std::string& prefix) {
    if (!IsTypeName(tokens_[position_])) {
      ADD_FAILURE() << "expected a node type, got '" << tokens_[position_] << "'";
      return false;
    }
    const std::string path = prefix + tokens_[position_++];
    if (position_ >= tokens_.size() || tokens_[position_] != "{") {
      ADD_FAILURE() << "expected '{' after " << path;
      return false;
    }
    ++position_;
    while (position_ < tokens_.size() && tokens_[position_] != "}") {
      if (!IsFieldName(tokens_[position_])) {
        ADD_FAILURE() << "expected a field name in " << path << ", got '" << tokens_[position_] << "'";
        return false;
      }
      const std::string field = path + " " + tokens_[position_++];
      if (position_ >= tokens_.size()) break;
      if (IsTypeName(tokens_[position_]) && tokens_[position_] != "TRUE" && tokens_[position_] != "FALSE") {
        if (!ReadNode(field + " ")) return false;
      } else if (tokens_[position_] == "[") {
        std::vector<std::string>& values = file_->multi_fields[field];
        for (++position_; position_ < tokens_.size() && tokens_[position_] != "]"; ++position_) {
          values.push_back(tokens_[position_]);
        }
        if (position_ >= tokens_.size()) break;
        ++position_;
      } else {
        std::string& value = file_->single_fields[field];
        while (position_ < tokens_.size() && !IsFieldName(tokens_[position_]) && tokens_[position_] != "}") {
          value += (value.empty() ? "" : " ") + tokens_[position_++];
        }
      }
    }
    if (position_ >= tokens_.size()) {
      ADD_FAILURE() << "unbalanced: " << path << " is not closed";
      return false;
    }
    ++position_;  // '}'
    return true;
  }

  std::vector<std::string> tokens_;
  size_t position_ = 0;
  VrmlFile* file_ = nullptr;
};

float ToFloat(const std::string& token) {
  float value = std::numeric_limits<float>::quiet_NaN();
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  EXPECT_TRUE(result.ec == std::errc() && result.ptr == token.data() + token.size()) << "'" << token << "'";
  return value;
}

std::vector<Eigen::Vector3f> Triples(const std::vector<std::string>& values) {
  EXPECT_EQ(values.size() % 3, 0u);
  std::vector<Eigen::Vector3f> triples;
  for (size_t i = 0; i + 2 < values.size(); i += 3) {
    triples.emplace_back(ToFloat(values[i]), ToFloat(values[i + 1]), ToFloat(values[i + 2]));
  }
  return triples;
}

class VrmlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTestDirectory(std::string("reconar_vrml_") +
                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Writes, reads back and checks the header line.
  VrmlFile WriteAndRead(const Mesh& mesh) {
    const std::string path = dir_ + "/mesh.wrl";
    EXPECT_TRUE(WriteVrml(path, mesh).ok());
    const Result<std::string> text = ReadFileToString(path);
    EXPECT_TRUE(text.ok());
    VrmlFile file;
    if (!text.ok()) return file;
    EXPECT_EQ(text->rfind("#VRML V2.0 utf8\n", 0), 0u);
    VrmlReader reader(Tokenize(*text));
    EXPECT_TRUE(reader.Read(&file));
    return file;
  }

  std::string dir_;
};

TEST_F(VrmlTest, TriangleMeshIsAnIndexedFaceSetWithExactValues) {
  for (const bool with_normals : {false, true}) {
    for (const bool with_colors : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "normals " << with_normals << " colours " << with_colors);
      const Mesh mesh = testing::RandomMesh(300, 600, with_normals, with_colors, 5);
      const VrmlFile file = WriteAndRead(mesh);
      const std::string faces = "Shape geometry IndexedFaceSet";
      EXPECT_EQ(file.single_fields.at(faces + " solid"), "FALSE");
      EXPECT_EQ(file.single_fields.at(faces + " ccw"), "TRUE");
      EXPECT_EQ(file.single_fields.at("Shape appearance Appearance material Material diffuseColor"), "0.8 0.8 0.8");

      const std::vector<Eigen::Vector3f> points = Triples(file.multi_fields.at(faces + " coord Coordinate point"));
      ASSERT_EQ(points.size(), mesh.positions.size());
      for (size_t i = 0; i < points.size(); ++i) ASSERT_EQ(points[i], mesh.positions[i]) << i;

      const std::vector<std::string>& indices = file.multi_fields.at(faces + " coordIndex");
      ASSERT_EQ(indices.size(), 4 * mesh.triangles.size());
      for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) ASSERT_EQ(indices[4 * t + k], std::to_string(mesh.triangles[t][k]));
        ASSERT_EQ(indices[4 * t + 3], "-1");
      }

      EXPECT_EQ(file.multi_fields.count(faces + " normal Normal vector"), with_normals ? 1u : 0u);
      if (with_normals) {
        EXPECT_EQ(file.single_fields.at(faces + " normalPerVertex"), "TRUE");
        EXPECT_EQ(Triples(file.multi_fields.at(faces + " normal Normal vector")), mesh.normals);
      }
      EXPECT_EQ(file.multi_fields.count(faces + " color Color color"), with_colors ? 1u : 0u);
      if (with_colors) {
        EXPECT_EQ(file.single_fields.at(faces + " colorPerVertex"), "TRUE");
        const std::vector<Eigen::Vector3f> colours = Triples(file.multi_fields.at(faces + " color Color color"));
        ASSERT_EQ(colours.size(), mesh.colors.size());
        for (size_t i = 0; i < colours.size(); ++i) {
          for (int c = 0; c < 3; ++c) ASSERT_EQ(std::lround(255.0f * colours[i][c]), mesh.colors[i][c]) << i;
        }
      }
    }
  }
}

TEST_F(VrmlTest, PointCloudIsAPointSet) {
  const Mesh mesh = testing::RandomMesh(100, 0, true, true, 9);
  const VrmlFile file = WriteAndRead(mesh);
  EXPECT_EQ(Triples(file.multi_fields.at("Shape geometry PointSet coord Coordinate point")), mesh.positions);
  EXPECT_EQ(file.multi_fields.at("Shape geometry PointSet color Color color").size(), 300u);
  EXPECT_EQ(file.single_fields.at("Shape appearance Appearance material Material emissiveColor"), "0.8 0.8 0.8");
  for (const auto& [path, values] : file.multi_fields) {
    EXPECT_EQ(path.find("IndexedFaceSet"), std::string::npos) << path;
    EXPECT_EQ(path.find("Normal"), std::string::npos) << path;  // PointSet has no normal field
  }
}

TEST_F(VrmlTest, RefusesInconsistentOrNonFiniteMeshesAndWritesNothing) {
  Mesh mesh = testing::RandomMesh(10, 5, false, true, 3);
  mesh.colors.pop_back();
  const std::string path = dir_ + "/refused.wrl";
  EXPECT_EQ(WriteVrml(path, mesh).code(), StatusCode::kInvalidArgument);
  mesh.colors.clear();
  mesh.positions[2].z() = std::numeric_limits<float>::infinity();
  const Status status = WriteVrml(path, mesh);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("vertex 2 has a non-finite position"), std::string::npos) << status.ToString();
  EXPECT_FALSE(ReadFileToString(path).ok());
}

}  // namespace
}  // namespace reconar
