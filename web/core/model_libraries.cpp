// The model loaders' libraries, compiled into the core from Debian's headers (libtinyobjloader-dev,
// libtinygltf-dev), where the desktop links Debian's shared builds of the same. tinygltf without its stb image
// decoding and writing: the loaders hand images to Context::decode_texture (model_texture.cpp here).
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>

#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
