// Writes the text cards' font metrics (media/card_layout.hpp) at build time: the font fontconfig gives for "DejaVu
// Sans" (the one cairo draws the desktop's cards with), its vertical metrics and, for every code point of the Basic
// Multilingual Plane it maps, the glyph's advance and ink extent across, in font units (unscaled, unhinted: what
// cairo measures with hint metrics and hinting off, scaled by the size). Also copies that font file, which the phone
// player's page draws its cards with.
//   arwb_card_font_table OUT.inc OUT.ttf
#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <cstdio>
#include <filesystem>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: arwb_card_font_table OUT.inc OUT.ttf\n");
    return 2;
  }
  FcInit();
  FcPattern* pattern = FcNameParse(reinterpret_cast<const FcChar8*>("DejaVu Sans"));
  FcConfigSubstitute(nullptr, pattern, FcMatchPattern);
  FcDefaultSubstitute(pattern);
  FcResult result;
  FcPattern* match = FcFontMatch(nullptr, pattern, &result);
  FcChar8* file = nullptr;
  FcChar8* family = nullptr;
  if (!match || FcPatternGetString(match, FC_FILE, 0, &file) != FcResultMatch ||
      FcPatternGetString(match, FC_FAMILY, 0, &family) != FcResultMatch ||
      std::string(reinterpret_cast<const char*>(family)) != "DejaVu Sans") {
    std::fprintf(stderr,
                 "arwb_card_font_table: fontconfig has no DejaVu Sans (Debian: apt install fonts-dejavu-core)\n");
    return 1;
  }
  const std::string path(reinterpret_cast<const char*>(file));
  FT_Library ft;
  FT_Face face;
  if (FT_Init_FreeType(&ft) || FT_New_Face(ft, path.c_str(), 0, &face) || !FT_IS_SCALABLE(face)) {
    std::fprintf(stderr, "arwb_card_font_table: cannot read %s\n", path.c_str());
    return 1;
  }
  std::FILE* out = std::fopen(argv[1], "w");
  if (!out) {
    std::fprintf(stderr, "arwb_card_font_table: cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(out, "// Written by arwb_card_font_table from %s (%s). Do not edit.\n", path.c_str(),
               face->family_name);
  std::fprintf(out, "constexpr CardFontFace kCardFontFace{%d, %d, %d, %d};\n", face->units_per_EM, face->ascender,
               face->descender, face->height);
  std::fprintf(out, "constexpr CardGlyph kCardGlyphs[] = {\n");
  int count = 0;
  FT_UInt index = 0;
  for (FT_ULong cp = FT_Get_First_Char(face, &index); index != 0; cp = FT_Get_Next_Char(face, cp, &index)) {
    if (cp > 0xFFFF) break;
    if (FT_Load_Glyph(face, index, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING)) continue;
    const FT_Glyph_Metrics& m = face->glyph->metrics;
    std::fprintf(out, "    {0x%04lx, %ld, %ld, %ld},\n", cp, long(m.horiAdvance), long(m.horiBearingX),
                 long(m.horiBearingX + m.width));
    ++count;
  }
  std::fprintf(out, "};\n");
  if (std::fclose(out) != 0 || count < 100) {
    std::fprintf(stderr, "arwb_card_font_table: %s: only %d glyphs\n", argv[1], count);
    return 1;
  }
  std::error_code ec;
  std::filesystem::copy_file(path, argv[2], std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) {
    std::fprintf(stderr, "arwb_card_font_table: cannot copy %s to %s (%s)\n", path.c_str(), argv[2],
                 ec.message().c_str());
    return 1;
  }
  FT_Done_Face(face);
  FT_Done_FreeType(ft);
  FcPatternDestroy(match);
  FcPatternDestroy(pattern);
  FcFini();   // fontconfig's caches freed: the sanitizer tree runs this tool with LeakSanitizer
  return 0;
}
