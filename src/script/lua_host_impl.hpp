// The Lua host's inside, shared by its files (internal to src/script):
//   lua_host.cpp       the state: made, called (load_chunk, pcall) and closed; host mode and script mode
//   lua_limits.cpp     the limits of one call: the counting allocator (the memory cap), the instruction budget and
//                      the wall-time bound (the hooks, armed by LuaState::arm_budget)
//   lua_libraries.cpp  the standard library as a scene gets it: trimmed to what stays inside the sandbox, guarded
//                      where one call could run unbounded, print and warn counted against the frame's allowance
#pragma once

#include "script/lua_host.hpp"

#include <cstddef>

namespace arwb::script {

// Lua's allocator for a state whose Host is `ud`: every block counted, growth refused past the cap in script mode.
void* counting_alloc(void* ud, void* ptr, std::size_t osize, std::size_t nsize);

// Opens the libraries a scene may use in a new state, in host mode, and sets its warning function; `host` is the
// state's Host.
void open_sandboxed_libraries(lua_State* L, Host* host);

}  // namespace arwb::script
