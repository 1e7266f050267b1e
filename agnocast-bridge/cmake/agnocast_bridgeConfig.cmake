# find_package(agnocast_bridge): agnocast::bridge_core and agnocast_add_bridge().
include(CMakeFindDependencyMacro)
find_dependency(agnocast)
find_dependency(CycloneDDS)
find_dependency(nlohmann_json)
find_dependency(spdlog)  # the service kit inside the core logs with it
include("${CMAKE_CURRENT_LIST_DIR}/agnocast_bridgeTargets.cmake")
include("${CMAKE_CURRENT_LIST_DIR}/AgnocastBridge.cmake")
