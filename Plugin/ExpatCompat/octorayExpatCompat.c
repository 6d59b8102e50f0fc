/*
 * Preloaded into ParaView 5.11 (LD_PRELOAD) on a system whose libexpat
 * defers reparsing (expat 2.6, and Debian 12's libexpat1 2.5.0-1+deb12u2 and
 * later, which backport it as the fix of CVE-2023-52425): VTK 9.2's XML
 * parser hands expat a whole buffer that ends in raw binary appended data
 * and stops it at the data's start marker; with reparse deferral expat goes
 * on tokenising into the binary bytes and fails ("not well-formed (invalid
 * token)"). ParaView's ranks exchange data in that form (RedistributeDataSet,
 * and the view's own redistribution for translucent rendering in parallel),
 * so on such a system every exchange fails. VTK 9.3 turns the deferral off
 * for its own parsers; this does the same for 9.2, for each parser created.
 *
 * Without reparse deferral expat is back to its behaviour before the fix:
 * parsing time can grow quadratically with a huge single token (the denial
 * of service of CVE-2023-52425), which matters for untrusted XML, not for
 * the data ParaView's own ranks write to each other.
 *
 * It defines octoray_expat_reparse_deferral_off, so that the plugin can tell
 * that it is loaded.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stddef.h>

typedef void* XML_Parser;
typedef unsigned char XML_Bool;
typedef char XML_Char;
typedef struct
{
  void* (*malloc_fcn)(size_t size);
  void* (*realloc_fcn)(void* ptr, size_t size);
  void (*free_fcn)(void* ptr);
} XML_Memory_Handling_Suite;

const int octoray_expat_reparse_deferral_off = 1;

/* The deferral switch where this libexpat has it (nothing to do otherwise). */
static XML_Parser WithoutDeferral(XML_Parser parser)
{
  typedef XML_Bool (*SetDeferral)(XML_Parser, XML_Bool);
  SetDeferral set = (SetDeferral)dlsym(RTLD_NEXT, "XML_SetReparseDeferralEnabled");
  if (parser && set)
  {
    set(parser, 0);
  }
  return parser;
}

XML_Parser XML_ParserCreate(const XML_Char* encoding)
{
  typedef XML_Parser (*Create)(const XML_Char*);
  Create create = (Create)dlsym(RTLD_NEXT, "XML_ParserCreate");
  return create ? WithoutDeferral(create(encoding)) : NULL;
}

XML_Parser XML_ParserCreateNS(const XML_Char* encoding, XML_Char separator)
{
  typedef XML_Parser (*Create)(const XML_Char*, XML_Char);
  Create create = (Create)dlsym(RTLD_NEXT, "XML_ParserCreateNS");
  return create ? WithoutDeferral(create(encoding, separator)) : NULL;
}

XML_Parser XML_ParserCreate_MM(
  const XML_Char* encoding, const XML_Memory_Handling_Suite* memory, const XML_Char* separator)
{
  typedef XML_Parser (*Create)(const XML_Char*, const XML_Memory_Handling_Suite*, const XML_Char*);
  Create create = (Create)dlsym(RTLD_NEXT, "XML_ParserCreate_MM");
  return create ? WithoutDeferral(create(encoding, memory, separator)) : NULL;
}
