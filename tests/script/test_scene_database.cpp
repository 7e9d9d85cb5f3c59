// Tests for the paper's XML database as a scene (src/script/scene_database.cpp) and the strict XML reader
// under it (src/script/xml_reader.cpp).
#include "scene_test_util.hpp"
#include "script/xml_reader.hpp"

#include <cstdio>

namespace arwb::script::test {
namespace {

// ---- the reader ----------------------------------------------------------------------------------------------

// The line of a "t.xml:LINE: message" error, or 0.
int line_of(const std::string& error) {
  int line = 0;
  return std::sscanf(error.c_str(), "t.xml:%d:", &line) == 1 ? line : 0;
}

TEST(XmlReader, ElementsAttributesTextCommentsAndLines) {
  const auto doc = parse_xml(R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- a comment -->
<a x="1" y='two &amp; three'>
  <b>hello</b><!-- inside -->
  <c/>
  <d><![CDATA[<raw> & stuff]]></d>
</a>
)",
                             "t.xml");
  ASSERT_TRUE(doc) << doc.error();
  EXPECT_EQ(doc->name, "a");
  EXPECT_EQ(doc->line, 3);
  ASSERT_TRUE(doc->attribute("y"));
  EXPECT_EQ(*doc->attribute("y"), "two & three");
  EXPECT_EQ(*doc->attribute("x"), "1");
  EXPECT_FALSE(doc->attribute("z"));
  ASSERT_EQ(doc->children.size(), 3u);
  EXPECT_EQ(doc->children[0].text, "hello");
  EXPECT_EQ(doc->children[0].line, 4);
  EXPECT_EQ(doc->children[1].name, "c");
  EXPECT_EQ(doc->children[1].line, 5);
  EXPECT_EQ(doc->children[2].text, "<raw> & stuff");
}

TEST(XmlReader, PredefinedEntitiesAndCharacterReferences) {
  const auto doc = parse_xml("<t>&lt;&gt;&amp;&apos;&quot; &#65;&#x42;&#xe9;&#x20AC;&#x1F600;</t>", "t.xml");
  ASSERT_TRUE(doc) << doc.error();
  EXPECT_EQ(doc->text, "<>&'\" AB\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80");
}

TEST(XmlReader, RefusesWhatItDoesNotSupport) {
  struct Case {
    const char* xml;
    int line;
    const char* words;
  };
  const Case cases[] = {
      {"<?xml version=\"1.0\"?>\n<!DOCTYPE db [<!ENTITY x SYSTEM \"file:///etc/passwd\">]>\n<db>&x;</db>", 2, "DOCTYPE"},
      {"<db>\n&nbsp;</db>", 2, "unknown entity &nbsp;"},
      {"<db>&#0;</db>", 1, "not a valid XML character"},
      {"<db>&#xD800;</db>", 1, "not a valid XML character"},
      {"<db>\n<row>\n</db>", 3, "</db> closes <row>"},
      {"<db>", 1, "never closed"},
      {"<db a=\"1\" a=\"2\"/>", 1, "given twice"},
      {"<db a=1/>", 1, "quoted"},
      {"<db/>\n<db/>", 2, "only one root"},
      {"text", 1, "root element"},
      {"<db>a & b</db>", 1, "'&'"},
      {"<db a=\"<\"/>", 1, "'<'"},
      {"\n<?xml version=\"1.0\"?><db/>", 2, "very start"},
      {"<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?><db/>", 1, "UTF-8 only"},
      {"<db><!-- a -- b --></db>", 1, "'--'"},
      {"<db>\x01</db>", 1, "control character"},
      {"<db>\n<!doctype db>\n</db>", 2, "DOCTYPE"},
      {"<db>\n<a>\n</a>\n</x>", 4, "</x> closes <db> opened on line 1"},
      {"<db>\n<a>x</a>", 2, "<db> (line 1) is never closed"},
      {"<db/>\njunk", 2, "only one root"},
      {"<db a=\"1\nb&c\"/>", 2, "'&'"},
      {"<db>\n<a>\n&#xZZ;</a></db>", 3, "bad character reference"},
  };
  for (const Case& c : cases) {
    const auto doc = parse_xml(c.xml, "t.xml");
    EXPECT_FALSE(doc) << c.xml;
    EXPECT_EQ(line_of(doc.error()), c.line) << c.xml << " -> " << doc.error();
    EXPECT_NE(doc.error().find(c.words), std::string::npos) << c.xml << " -> " << doc.error();
  }
}

TEST(XmlReader, DeepNestingIsRefusedNotOverflowed) {
  std::string xml;
  for (int i = 0; i < 10000; ++i) xml += "<a>";
  const auto doc = parse_xml(xml, "t.xml");
  EXPECT_FALSE(doc);
  EXPECT_NE(doc.error().find("nested"), std::string::npos) << doc.error();
}

TEST(XmlReader, HostileInputIsRefusedNotCrashed) {
  // Every prefix of a document, and bytes flipped through it: each either parses or names a line in the text.
  const std::string good = R"(<?xml version="1.0"?>
<database dictionary="ARUCO_ORIGINAL"><!-- c -->
  <row a='1'><id>&#55;</id><resource><![CDATA[media/a.png]]></resource></row>
</database>
)";
  const int lines = 5;
  for (size_t n = 0; n <= good.size(); ++n) {
    std::string t = good.substr(0, n);
    for (const char flip : {'\0', '<', '&', '>', '"', '/', '\xff'}) {
      if (n < good.size()) t = good.substr(0, n) + flip + good.substr(n + 1);
      const auto doc = parse_xml(t, "t.xml");
      if (doc) continue;
      EXPECT_GE(line_of(doc.error()), 1) << t << " -> " << doc.error();
      EXPECT_LE(line_of(doc.error()), lines) << t << " -> " << doc.error();
    }
  }
}

// ---- the database as a scene ---------------------------------------------------------------------------------

struct DatabaseScene : SceneFixture {
  DatabaseScene() {
    make_png(dir.path() / "media/painting.png", 80, 40);
    make_png(dir.path() / "media/a&b.png", 30, 30);
    make_avi(dir.path() / "media/clip.avi");
  }
};

TEST(SceneDatabase, GoodRowsLoadAsOnMarkerMedia) {
  DatabaseScene s;
  const auto p = s.write("db.xml", R"(<?xml version="1.0"?>
<database dictionary="ARUCO_ORIGINAL">
  <row><id>7</id><resource>media/painting.png</resource></row>
  <row><id>20</id><resource>https://opencv.org</resource></row>
  <row><id> 8 </id><resource>
      media/clip.avi
  </resource></row>
</database>
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error << "\n" << s.console();
  EXPECT_TRUE(s.runtime.status().console.empty()) << s.console();
  EXPECT_EQ(s.runtime.dictionary(), "ARUCO_ORIGINAL");
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].ids, "7");
  EXPECT_EQ(rows[0].media, "image media/painting.png");
  EXPECT_EQ(rows[0].placement.rfind("on_marker", 0), 0u);
  EXPECT_EQ(rows[0].line, 3);
  EXPECT_EQ(rows[1].line, 4);
  EXPECT_EQ(rows[2].media, "video media/clip.avi (loop)");

  const auto ov = s.update({track(7, 100, 100), track(20, 300, 100), track(8, 500, 100)}, enters({7, 8, 20}));
  ASSERT_EQ(ov.size(), 3u) << s.console();
  const Overlay* o7 = find_overlay(ov, 7);
  ASSERT_TRUE(o7 && o7->content);
  EXPECT_EQ(o7->media.kind, MediaKind::image);
  EXPECT_EQ(o7->place.kind, PlaceKind::on_marker);
  EXPECT_EQ(o7->content->size(), cv::Size(80, 40));
  const Overlay* o20 = find_overlay(ov, 20);
  ASSERT_TRUE(o20 && o20->content);
  EXPECT_EQ(o20->media.kind, MediaKind::web);
  EXPECT_EQ(o20->media.url, "https://opencv.org");
  const Overlay* o8 = find_overlay(ov, 8);
  ASSERT_TRUE(o8 && o8->content);
  EXPECT_EQ(o8->media.kind, MediaKind::video);
  EXPECT_TRUE(o8->media.loop);
}

TEST(SceneDatabase, BadRowsAreReportedWithTheirLineAndSkipped) {
  DatabaseScene s;
  const auto p = s.write("db.xml", R"(<database>
  <row><id>x7</id><resource>media/painting.png</resource></row>
  <row><id>9</id></row>
  <row><id>10</id><resource>../secret.png</resource></row>
  <row><id>2000</id><resource>media/painting.png</resource></row>
  <row><id>11</id><resource>ftp://example.org/x</resource></row>
  <row><id>12</id><resource>media/nothing.png</resource></row>
  <row><resource>media/painting.png</resource></row>
  <row><id>7</id><resource>media/painting.png</resource></row>
  <other/>
</database>
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_TRUE(s.runtime.status().error.empty());
  EXPECT_TRUE(s.runtime.dictionary().empty());
  auto expect = [&](const std::string& text) { EXPECT_TRUE(s.has(text)) << text << "\n" << s.console(); };
  expect("db.xml:2: id 'x7' is not an integer; row skipped");
  expect("db.xml:3: row for id 9 has no resource; row skipped");
  expect("db.xml:4: ../secret.png: leaves the scene's folder; row skipped");
  expect("db.xml:5: id 2000 is not a marker of ARUCO_ORIGINAL (ids 0 to 1023); row skipped");
  expect("db.xml:6: ftp://example.org/x");
  expect("db.xml:7: media/nothing.png: no such file; row skipped");
  expect("db.xml:8: row without an <id>; row skipped");
  expect("db.xml:10: unexpected element <other>");
  EXPECT_EQ(s.lines("row skipped").size(), 7u) << s.console();
  // The refused rows stay in the Scene panel, skipped, with their reasons; one row works.
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 8u);
  int ok = 0;
  for (const MappingRow& r : rows) {
    if (r.health == MappingHealth::ok) {
      ++ok;
      EXPECT_EQ(r.line, 9);
    } else {
      EXPECT_EQ(r.health, MappingHealth::skipped);
      EXPECT_NE(r.reason.find("row skipped"), std::string::npos) << r.reason;
    }
  }
  EXPECT_EQ(ok, 1);
  EXPECT_EQ(rows[1].ids, "9");   // read before the row was refused for its resource
  EXPECT_EQ(rows[3].ids, "?");   // id 2000 is not in the dictionary
  EXPECT_EQ(rows[1].reason_line, 3);
  const auto ov = s.update({track(7, 100, 100), track(9, 300, 100)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].marker_id, 7);
}

TEST(SceneDatabase, DoctypeIsRefusedWithItsLine) {
  DatabaseScene s;
  const auto p = s.write("db.xml", R"(<?xml version="1.0"?>
<!DOCTYPE database [ <!ENTITY e SYSTEM "file:///etc/passwd"> ]>
<database><row><id>7</id><resource>&e;</resource></row></database>
)");
  EXPECT_FALSE(s.runtime.load(p));
  EXPECT_FALSE(s.runtime.status().ok);
  EXPECT_NE(s.runtime.status().error.find("/db.xml:2: DOCTYPE declarations are not allowed"), std::string::npos)
      << s.runtime.status().error;
  EXPECT_EQ(s.runtime.status().error_line, 2);
}

TEST(SceneDatabase, EntitiesAreDecoded) {
  DatabaseScene s;
  const auto p = s.write("db.xml", R"(<database dictionary="aruco_original">
  <row><id>&#55;</id><resource>media/a&amp;b.png</resource></row>
  <row><id>8</id><resource>https://example.org/?a=1&amp;b=&#x32;</resource></row>
</database>
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error << "\n" << s.console();
  const auto ov = s.update({track(7, 100, 100), track(8, 300, 100)});
  ASSERT_EQ(ov.size(), 2u) << s.console();
  EXPECT_EQ(find_overlay(ov, 7)->media.source, "media/a&b.png");
  EXPECT_EQ(find_overlay(ov, 7)->content->size(), cv::Size(30, 30));
  EXPECT_EQ(find_overlay(ov, 8)->media.url, "https://example.org/?a=1&b=2");
}

TEST(SceneDatabase, BrokenFilesFailWithFileAndLineAndTheLastSceneStays) {
  DatabaseScene s;
  const auto good = s.write("good.xml", "<database><row><id>7</id><resource>media/painting.png</resource></row></database>");
  ASSERT_TRUE(s.runtime.load(good)) << s.runtime.status().error;
  struct Case {
    const char* xml;
    const char* error;
  };
  const Case cases[] = {
      {"<database>\n<row><id>7</id>\n</database>", "bad.xml:3: </database> closes <row>"},
      {"<?xml version=\"1.0\"?>\n<table/>", "bad.xml:2: the root element must be <database>, not <table>"},
      {"<database dictionary=\"NOPE\"/>", "bad.xml:1: dictionary: unknown dictionary 'NOPE'"},
      {"<database>\n<row><id>&bogus;</id></row></database>", "bad.xml:2: unknown entity &bogus;"},
  };
  for (const Case& c : cases) {
    const auto bad = s.write("bad.xml", c.xml);
    EXPECT_FALSE(s.runtime.load(bad)) << c.xml;
    const std::string want = std::string("/").append(c.error);
    EXPECT_NE(s.runtime.status().error.find(want), std::string::npos) << s.runtime.status().error;
    EXPECT_TRUE(s.runtime.status().ok);
    EXPECT_EQ(s.runtime.status().file, good);
    const auto ov = s.update({track(7, 100, 100)});
    ASSERT_EQ(ov.size(), 1u);
    EXPECT_EQ(ov[0].media.kind, MediaKind::image);
  }
}

TEST(SceneDatabase, ReloadIfChangedWatchesTheDatabaseToo) {
  DatabaseScene s;
  const auto p = s.write("db.xml", "<database><row><id>7</id><resource>media/painting.png</resource></row></database>");
  ASSERT_TRUE(s.runtime.load(p));
  EXPECT_FALSE(s.runtime.reload_if_changed());
  s.write("db.xml", "<database>\n<row><id>7</id><resource>https://opencv.org/releases</resource></row>\n</database>");
  EXPECT_TRUE(s.runtime.reload_if_changed());
  const auto ov = s.update({track(7, 100, 100)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].media.kind, MediaKind::web);
}

}  // namespace
}  // namespace arwb::script::test
