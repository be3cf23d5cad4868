// docs/scene-format.md against the loader's key tables (scene_key_docs): every
// key table of the docs lists exactly the keys of its object, in the loader's
// order, with the loader's type, unit and default, and each default is the value the
// description structs start from; the timeline's action table
// lists each action's keys; the objects documented in prose name all their keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "odemag/scene.h"
#include "engine/scene/scene_text.h"

namespace {

using odemag::SceneKeyDoc;

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

// One heading of the docs: its text up to " (" ("permanent (hard magnet)" ->
// "permanent"), everything under it, and its tables.
struct Section {
  std::string text;
  std::vector<Table> tables;
};

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(' ');
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(' ') - a + 1);
}

// The cells of a table row, split at the '|' that are not escaped ("\|").
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  for (size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
      cell += "\\|";
      ++i;
    } else if (line[i] == '|') {
      out.push_back(trim(cell));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return out;
}

std::map<std::string, Section> read_docs() {
  const std::string path = std::string(ODEMAG_SOURCE_DIR) + "/docs/scene-format.md";
  std::ifstream in(path);
  EXPECT_TRUE(in) << "cannot open " << path;
  std::map<std::string, Section> sections;
  Section* current = nullptr;
  bool in_table = false;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) {
      std::string heading = trim(line.substr(line.find_first_not_of('#')));
      heading = heading.substr(0, heading.find(" ("));
      current = &sections[heading];
      in_table = false;
      continue;
    }
    if (!current) continue;
    current->text += line + "\n";
    if (line.rfind("|", 0) != 0) {
      in_table = false;
      continue;
    }
    if (!in_table) {
      current->tables.push_back({cells(line), {}});
      in_table = true;
    } else if (line.rfind("|---", 0) != 0) {
      current->tables.back().rows.push_back(cells(line));
    }
  }
  return sections;
}

std::string unquote(const std::string& cell) {
  if (cell.size() >= 2 && cell.front() == '`' && cell.back() == '`') return cell.substr(1, cell.size() - 2);
  return cell;
}

std::vector<SceneKeyDoc> keys_of(const std::string& section) {
  std::vector<SceneKeyDoc> keys;
  for (const SceneKeyDoc& d : odemag::scene_key_docs())
    if (d.section == section) keys.push_back(d);
  return keys;
}

// The objects whose keys the docs list in a table "| key | type | ..." under a heading.
const std::map<std::string, std::string> kKeyTables = {
    {"", "Top level"},           {"materials.permanent", "permanent"}, {"materials.soft", "soft"}, {"materials.linear", "linear"},
    {"materials.inert", "inert"}, {"bodies[]", "Bodies"},              {"solver", "solver"},
    {"bodies[].shape.mesh", "Meshes"}, {"bodies[].shape.compound[]", "Compounds"},
    {"simulation", "simulation"}, {"simulation.contact", "contact"},
    {"camera", "camera"},
    {"render", "render"},         {"outcomes[]", "outcomes"},           {"joints[]", "joints"},
};
// The objects the docs describe in prose under a heading.
const std::map<std::string, std::string> kProse = {
    {"bodies[].shape", "Bodies"},
    {"bodies[].shape.cylinder", "Bodies"},
    {"bodies[].coils[].loop", "Coils"},
    {"bodies[].coils[].solenoid", "Coils"},
    {"bodies[].coils[].circular_coil", "Coils"},
    {"bodies[].coils[].rounded_rectangle", "Coils"},
    {"bodies[].coils[].segment", "Coils"},
    {"bodies[].coils[].arc", "Coils"},
    {"timeline[].keys[]", "timeline"},
    {"outcomes[].count_above", "outcomes"},
    {"outcomes[].distance", "outcomes"},
    {"outcomes[].height", "outcomes"},
    {"outcomes[].speed", "outcomes"},
    {"outcomes[].contact_count", "outcomes"},
    {"outcomes[].force", "outcomes"},
    {"outcomes[].moment", "outcomes"},
};
const std::string kEventPrefix = "timeline[].";

TEST(SceneKeys, EveryObjectIsDocumented) {
  std::set<std::string> sections;
  for (const SceneKeyDoc& d : odemag::scene_key_docs()) sections.insert(d.section);
  EXPECT_GE(sections.size(), kKeyTables.size() + kProse.size());
  for (const std::string& s : sections) {
    const bool event = s.rfind(kEventPrefix, 0) == 0 && s != "timeline[].keys[]";
    EXPECT_TRUE(kKeyTables.count(s) || kProse.count(s) || event)
        << "scene object \"" << s << "\" has no place in docs/scene-format.md (add it to this test)";
  }
}

TEST(SceneKeys, KeyTablesMatchTheLoader) {
  const auto docs = read_docs();
  for (const auto& [section, heading] : kKeyTables) {
    SCOPED_TRACE("docs/scene-format.md \"" + heading + "\" vs scene object \"" + section + "\"");
    ASSERT_TRUE(docs.count(heading)) << "no heading " << heading;
    const Table* table = nullptr;
    for (const Table& t : docs.at(heading).tables)
      if (!t.header.empty() && t.header[0] == "key") table = &t;
    ASSERT_NE(table, nullptr) << "no key table under " << heading;
    std::map<std::string, size_t> column;
    for (size_t c = 0; c < table->header.size(); ++c) column[table->header[c]] = c;
    ASSERT_TRUE(column.count("type") && column.count("default"));

    const std::vector<SceneKeyDoc> keys = keys_of(section);
    std::vector<std::string> code_names, doc_names;
    for (const SceneKeyDoc& k : keys) code_names.push_back(k.key);
    for (const auto& row : table->rows) doc_names.push_back(row.empty() ? "" : unquote(row[0]));
    EXPECT_EQ(doc_names, code_names) << "the docs' keys (left) differ from the loader's (right)";

    for (const auto& row : table->rows) {
      const std::string name = unquote(row[0]);
      const auto k = std::find_if(keys.begin(), keys.end(), [&](const SceneKeyDoc& d) { return d.key == name; });
      if (k == keys.end()) continue;
      ASSERT_EQ(row.size(), table->header.size()) << "row " << name;
      EXPECT_EQ(row[column["type"]], k->type) << "type of " << name;
      EXPECT_EQ(row[column["default"]], k->default_value) << "default of " << name;
      EXPECT_EQ(column.count("unit") ? row[column["unit"]] : std::string(), k->unit) << "unit of " << name;
      EXPECT_EQ(k->required, k->default_value == "**required**") << "required of " << name;
    }
  }
}

// The docs' default of every plain key is the value the description structs
// start from: a key left out of a file gets what the docs say. Numbers are
// compared as parsed doubles, so "`1e-6`" matches 1e-06; a default the docs
// write as a bare word (`auto`) matches the string "auto".
TEST(SceneKeys, DocumentedDefaultsAreTheStructDefaults) {
  int compared = 0;
  for (const SceneKeyDoc& k : odemag::scene_key_docs()) {
    const std::string& doc = k.default_value;
    if (k.struct_default.empty() || doc.size() < 2 || doc.front() != '`' || doc.back() != '`') continue;
    const std::string text = unquote(doc);
    const nlohmann::json actual = nlohmann::json::parse(k.struct_default);
    nlohmann::json documented = nlohmann::json::parse(text, nullptr, false);
    if (documented.is_discarded()) documented = text;  // a bare word
    // JSON integers and doubles compare by value; arrays element by element.
    EXPECT_EQ(documented, actual) << k.section << "." << k.key << ": the docs say " << doc
                                  << ", the structs start from " << k.struct_default;
    ++compared;
  }
  EXPECT_GT(compared, 40) << "too few defaults compared: the docs' format changed?";
}

TEST(SceneKeys, TimelineActionsMatchTheLoader) {
  const auto docs = read_docs();
  ASSERT_TRUE(docs.count("timeline"));
  const Table* table = nullptr;
  for (const Table& t : docs.at("timeline").tables)
    if (t.header.size() >= 2 && t.header[0] == "action" && t.header[1] == "keys") table = &t;
  ASSERT_NE(table, nullptr) << "no action table under timeline";

  std::set<std::string> code_actions, doc_actions;
  for (const SceneKeyDoc& d : odemag::scene_key_docs())
    if (d.section.rfind(kEventPrefix, 0) == 0 && d.section != "timeline[].keys[]")
      code_actions.insert(d.section.substr(kEventPrefix.size()));
  for (const auto& row : table->rows) {
    const std::string action = unquote(row.at(0));
    doc_actions.insert(action);
    SCOPED_TRACE("timeline action " + action);
    // Every event has "time" and "action", documented above the table.
    std::vector<std::string> code_keys, doc_keys;
    for (const SceneKeyDoc& k : keys_of(kEventPrefix + action))
      if (k.key != "time" && k.key != "action") code_keys.push_back(k.key);
    const std::regex key("`([a-z_]+)`");
    for (auto m = std::sregex_iterator(row.at(1).begin(), row.at(1).end(), key); m != std::sregex_iterator(); ++m)
      doc_keys.push_back((*m)[1]);
    EXPECT_EQ(doc_keys, code_keys) << "the docs' keys (left) differ from the loader's (right)";
  }
  EXPECT_EQ(doc_actions, code_actions);
}

TEST(SceneKeys, ProseNamesEveryKey) {
  const auto docs = read_docs();
  for (const auto& [section, heading] : kProse) {
    ASSERT_TRUE(docs.count(heading)) << "no heading " << heading;
    const std::string& text = docs.at(heading).text;
    const std::vector<SceneKeyDoc> keys = keys_of(section);
    EXPECT_FALSE(keys.empty()) << section;
    for (const SceneKeyDoc& k : keys)
      EXPECT_TRUE(text.find("`" + k.key + "`") != std::string::npos ||
                  text.find("\"" + k.key + "\"") != std::string::npos)
          << "docs/scene-format.md \"" << heading << "\" does not name " << section << "." << k.key;
  }
}

}  // namespace
