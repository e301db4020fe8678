"""`CoSimulation`: one Co-Simulation instance of an FMI 2.0 or an FMI 3.0 FMU behind the same calls.

The package's modules drive the FMUs point by point with FMPy's slaves. FMI 2.0 (`FMU2Slave`) and
FMI 3.0 (`FMU3Slave`) name their calls differently (`setReal` / `setFloat64`), start differently
(`setupExperiment` exists only in FMI 2.0) and read Enumerations differently (FMI 2.0 Integer,
FMI 3.0 Int64). This class takes the FMI 2.0 names and sends each call to the version the model
description declares, so that `ACTUATOR_FMUS_FMI=3` runs every module on the FMI 3.0 FMUs.
Values, units and value references are the same in both versions for every variable the
package reads or writes (the Float64 value references are the FMI 2.0 Real ones; the others are
taken from the model description by name).
"""

from fmpy import read_model_description


class CoSimulation:
    """An FMU instance (not yet instantiated) for `unzip_directory`, described by `md`."""

    def __init__(self, unzip_directory, instance_name, md=None):
        self.md = md if md is not None else read_model_description(unzip_directory)
        self.fmi3 = self.md.fmiVersion.startswith("3")
        if self.fmi3:
            from fmpy.fmi3 import FMU3Slave as Slave
        else:
            from fmpy.fmi2 import FMU2Slave as Slave
        self.fmu = Slave(guid=self.md.guid, unzipDirectory=unzip_directory,
                         modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance_name)
        self.enumerations = {v.valueReference for v in self.md.modelVariables if v.type == "Enumeration"}

    def instantiate(self, log=None, loggingOn=False):
        """`log`: an object with FMI 2.0 `callbacks` or an FMI 3.0 `log_message` callable (FMPy's
        printing logger if None or if it has none for this version)."""
        if self.fmi3:
            self.fmu.instantiate(loggingOn=loggingOn, logMessage=getattr(log, "log_message", None))
        else:
            self.fmu.instantiate(callbacks=getattr(log, "callbacks", None), loggingOn=loggingOn)

    def enterInitializationMode(self, startTime=0.0):
        """FMI 2.0's `setupExperiment` and `enterInitializationMode` in one."""
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=startTime)
        else:
            self.fmu.setupExperiment(startTime=startTime)
            self.fmu.enterInitializationMode()

    def exitInitializationMode(self):
        self.fmu.exitInitializationMode()

    def setReal(self, vrs, values):
        (self.fmu.setFloat64 if self.fmi3 else self.fmu.setReal)(list(vrs), [float(x) for x in values])

    def getReal(self, vrs):
        return (self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)(list(vrs))

    def setInteger(self, vrs, values):
        """Integers and Enumerations (FMI 3.0: Int32 and Int64)."""
        values = [int(x) for x in values]
        if not self.fmi3:
            self.fmu.setInteger(list(vrs), values)
            return
        for vr, value in zip(vrs, values):
            (self.fmu.setInt64 if vr in self.enumerations else self.fmu.setInt32)([vr], [value])

    def getInteger(self, vrs):
        if not self.fmi3:
            return self.fmu.getInteger(list(vrs))
        return [(self.fmu.getInt64 if vr in self.enumerations else self.fmu.getInt32)([vr])[0] for vr in vrs]

    def setBoolean(self, vrs, values):
        self.fmu.setBoolean(list(vrs), [bool(x) for x in values])

    def getBoolean(self, vrs):
        return self.fmu.getBoolean(list(vrs))

    def getDirectionalDerivative(self, unknowns, knowns, seed):
        return self.fmu.getDirectionalDerivative(list(unknowns), list(knowns), list(seed))

    def doStep(self, currentCommunicationPoint, communicationStepSize):
        self.fmu.doStep(currentCommunicationPoint, communicationStepSize)

    def reset(self):
        self.fmu.reset()

    def terminate(self):
        self.fmu.terminate()

    def freeInstance(self):
        self.fmu.freeInstance()

    @property
    def fmiCallLogger(self):
        return self.fmu.fmiCallLogger

    @fmiCallLogger.setter
    def fmiCallLogger(self, logger):
        # FMPy's trace of every FMI call, on the slave that makes them.
        self.fmu.fmiCallLogger = logger

    def __getattr__(self, name):
        # Anything else is the version's own call (getFMUstate in FMI 2.0, getFMUState in 3.0).
        if name == "fmu":  # not set yet: no slave to ask
            raise AttributeError(name)
        return getattr(self.fmu, name)
