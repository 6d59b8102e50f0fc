"""Why the "Octree Volume" representation keeps no points for updates, in
pvbatch on the bundled LiDAR particles: its mapper has KeepPointsForUpdates
off, and a move of the points in place (the array of a data set that a
script owns, as a simulation coupled to pvbatch moves its points) is a
build, because every pipeline update hands the mapper a new data set.

usage: plugin_keep_points.py PLUGIN DATA_DIR
"""
import sys

from paraview.simple import *  # noqa: F401,F403

from plugin_checks import check, finish

plugin, data = sys.argv[1:3]
LoadPlugin(plugin, remote=False, ns=globals())

import octoray  # noqa: E402  (the build's Python package, on PYTHONPATH)

cloud = servermanager.Fetch(OctorayParticleReader(FileNames=[data + "/Particles/lidar_simple.particles"]))
source = TrivialProducer()
source.GetClientSideObject().SetOutput(cloud)
view = CreateView("RenderView")
view.ViewSize = [200, 150]
display = Show(source, view)
display.SetRepresentationType("Octree Volume")
display.Backend = "CPU"
display.LeafDepth = 6
view.ResetCamera()
Render(view)
# The Octree Volume representation (client-server wrapped only: reached as
# its ParaView base class, whose actor holds the mapper).
mapper = display.GetClientSideObject().GetActiveRepresentation().GetActor().GetMapper()
check("the mapper is octoray's (%s)" % mapper.GetClassName(), isinstance(mapper, octoray.vtkOctreeVolumeMapper))
check("it keeps no points for updates", not mapper.GetKeepPointsForUpdates())

builds, updates = mapper.GetNumberOfBuilds(), mapper.GetNumberOfUpdates()
points = cloud.GetPoints()
for i in range(points.GetNumberOfPoints()):
    x, y, z = points.GetPoint(i)
    points.SetPoint(i, x + 0.01, y, z)
points.Modified()
source.MarkModified(source)
Render(view)
cost = (mapper.GetNumberOfBuilds() - builds, mapper.GetNumberOfUpdates() - updates)
check("a move in place is a build: (builds, updates) = %s" % (cost,), cost == (1, 0))

finish()
